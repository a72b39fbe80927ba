"""examples/elimco-bench and examples/enki-hose built with the CLI, and every service called with it."""

from __future__ import annotations

import json
import math
import shutil
from pathlib import Path

import pytest

from tests.cli import run
from tests.conftest import EXAMPLES

BENCH = EXAMPLES / "elimco-bench"
HOSE = EXAMPLES / "enki-hose"


@pytest.fixture(scope="module")
def store(tmp_path_factory: pytest.TempPathFactory) -> Path:
    target = tmp_path_factory.mktemp("elimco") / "store"
    result = run("build", BENCH / "manifest.toml", "--store", target)
    assert result.returncode == 0, result.stderr
    for name, kind in (
        ("cable-list.xlsx", "elimco-cable-list"),
        ("pin_info.xml", "pin-info"),
        ("cable_info.xml", "cable-info"),
        ("path_info.xml", "path-info"),
    ):
        assert name in result.stdout and kind in result.stdout
    return target


def call(target: Path, *args: str) -> dict[str, object]:
    result = run("call", target, *args)
    data: dict[str, object] = json.loads(result.stdout)
    # The exit status follows the answer: 1 when it says success: false.
    assert result.returncode == (0 if data.get("success", True) else 1), result.stderr
    return data


def position(pose: object) -> tuple[float, float, float]:
    assert isinstance(pose, dict)
    p = pose["position"]
    return (p["x"], p["y"], p["z"])


def test_the_profile_and_its_services_are_listed() -> None:
    result = run("services")
    assert result.returncode == 0
    for name in (
        "load_files",
        "get_pin_positions",
        "pin_frames",
        "get_cable_list",
        "get_path_positions",
        "hose_info",
    ):
        assert name in result.stdout


def test_get_pin_positions(store: Path) -> None:
    data = call(store, "get_pin_positions", "use_centroid=true")
    assert data["success"] is True and data["frame"] == "pins_centroid"
    pins = {p["name"]: p for p in data["pins"]}  # type: ignore[attr-defined]
    assert position(pins["A350VC-A"]["pose"]) == pytest.approx((-0.334, -0.722, 0.0))
    assert position(pins["A918VC1A"]["pose"]) == pytest.approx((-0.235, 1.204, 0.0))
    drawing = call(store, "get_pin_positions", "use_centroid=false", "pin_connector_distance=0.05")
    pins = {p["name"]: p for p in drawing["pins"]}  # type: ignore[attr-defined]
    assert position(pins["A1UZ3C"]["pose"]) == pytest.approx((12.35, 2.002, 0.0))
    assert position(drawing["centroid"]) == pytest.approx((11.939, 2.724, 0.0))


def test_pin_frames(store: Path) -> None:
    data = call(store, "pin_frames")
    names = [(f["name"], f["parent"]) for f in data["frames"]]  # type: ignore[attr-defined]
    assert names[0] == ("drawing", "pins_centroid")
    assert ("pin_pin_1_doble_a", "pin_pin_1_doble") in names
    assert len(names) == 9


def test_get_cable_list(store: Path) -> None:
    data = call(store, "get_cable_list")
    assert [(c["name"], c["length"], c["path"]) for c in data["cables"]] == [  # type: ignore[attr-defined]
        ("A4351-1669", 1.504, 0),
        ("A4351-2401", 1.057, 1),
        ("A4351-1677", 1.668, 2),
    ]


def test_get_path_positions(store: Path) -> None:
    data = call(store, "get_path_positions", "cable=A4351-1669")
    assert data["pins"] == ["A918VC1A", "A1UZ3B"]
    assert data["segment_lengths"] == [1.2] and data["total_length"] == 1.2
    end = position(data["poses"][1])  # type: ignore[index]
    assert end == pytest.approx((0.461 - 0.05 / math.sqrt(5), 0.276 + 0.025 / math.sqrt(5), 0.0))
    missing = call(store, "get_path_positions", "cable=nope")
    assert missing["success"] is False


def test_load_files_on_a_store_opened_for_reading(store: Path) -> None:
    data = call(store, "load_files", f"paths={BENCH / 'pin_info.xml'}")
    assert data["success"] is False and "read-only" in str(data["message"])


def test_load_files_on_a_manifest_built_in_memory() -> None:
    data = call(
        BENCH / "manifest.toml", "load_files", f"paths={BENCH / 'pin_info.xml'},{BENCH / 'path_info.xml'}"
    )
    assert data == {
        "success": True,
        "message": "loaded 2 file(s) into pin_info.xml, path_info.xml",
        "sources": ["pin_info.xml", "path_info.xml"],
    }


def test_a_bad_file_leaves_the_built_store(tmp_path: Path) -> None:
    cell = tmp_path / "cell"
    shutil.copytree(BENCH, cell)
    target = tmp_path / "store"
    assert run("build", cell / "manifest.toml", "--store", target).returncode == 0
    text = (cell / "path_info.xml").read_text(encoding="utf-8")
    (cell / "path_info.xml").write_text(text.replace('length="393"', 'length="293"'), encoding="utf-8")
    result = run("build", cell / "manifest.toml", "--store", target)
    assert result.returncode == 2
    assert result.stderr.strip().startswith(
        f"cadkg: error: {cell / 'path_info.xml'}:10: the segment lengths of path 2"
    )
    assert "Traceback" not in result.stderr
    assert call(target, "get_path_positions", "cable=2")["total_length"] == 1.168


def test_a_corrupt_cable_list_is_a_located_error(tmp_path: Path) -> None:
    cell = tmp_path / "cell"
    shutil.copytree(BENCH, cell)
    whole = (cell / "cable-list.xlsx").read_bytes()
    (cell / "cable-list.xlsx").write_bytes(whole[: len(whole) // 3])
    result = run("build", cell / "manifest.toml", "--store", tmp_path / "store")
    assert result.returncode == 2
    assert f"{cell / 'cable-list.xlsx'}: corrupt workbook" in result.stderr
    assert not (tmp_path / "store" / "CURRENT").exists()


def test_enki_hose_info() -> None:
    data = call(HOSE / "manifest.toml", "hose_info", "product=HX-16")
    assert data == {
        "success": True,
        "message": "ok",
        "product": "HX-16",
        "diameter": 0.016,
        "length": 2.5,
        "material": "EPDM",
        "bend_radius": 0.08,
    }
