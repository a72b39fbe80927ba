"""Every .msg/.srv of ros2/ parses with rosidl_adapter (the ROS parser, present in .venv-ros)."""

from __future__ import annotations

from pathlib import Path

import pytest
from rosidl_adapter.parser import parse_message_string, parse_service_string

PACKAGES = Path(__file__).resolve().parents[3] / "ros2"


@pytest.mark.parametrize(
    "path", sorted(PACKAGES.glob("*/msg/*.msg")) + sorted(PACKAGES.glob("*/srv/*.srv")), ids=lambda p: p.name
)
def test_parses(path: Path) -> None:
    package = path.parent.parent.name
    if path.suffix == ".msg":
        spec = parse_message_string(package, path.stem, path.read_text())
        assert spec.fields
    else:
        service = parse_service_string(package, path.stem, path.read_text())
        assert {"success", "message"} <= {f.name for f in service.response.fields}
