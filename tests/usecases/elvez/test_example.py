"""The bundled ELVEZ cell through the command line: build a store from the cell's own files,
call the services (the cursor kept per client between calls), validate, query.

The expected poses are the hand computations of examples/elvez-cell/README.md.
"""

from __future__ import annotations

import json
import math
import shutil
from pathlib import Path
from typing import Any

import pytest
from click.testing import CliRunner, Result

from cadkg.cli import cli
from cadkg.graph import KnowledgeGraph
from cadkg.services.session import Session
from cadkg.usecases.elvez.services import element_meshes, platform_frames
from tests.conftest import EXAMPLES

MANIFEST = EXAMPLES / "elvez-cell" / "manifest.toml"
KINDS = (
    "elvez-scene",
    "elvez-ids",
    "elvez-definitions",
    "elvez-harnesses",
    "elvez-components",
    "elvez-sequence",
    "elvez-mesh",
)


def run(*args: str | Path) -> Result:
    """``cadkg ARGS`` in this process (click's runner): what a user would see, without a new Python."""
    return CliRunner().invoke(cli, [str(a) for a in args], catch_exceptions=False)


@pytest.fixture(scope="module")
def store(tmp_path_factory: pytest.TempPathFactory) -> Path:
    target = tmp_path_factory.mktemp("elvez") / "store"
    result = run("build", MANIFEST, "--store", target)
    assert result.exit_code == 0, result.output
    for kind in KINDS:
        assert kind in result.stdout
    assert "warning" not in result.stderr
    return target


def call(store: Path, *args: str) -> dict[str, Any]:
    result = run("call", store, *args)
    data: dict[str, Any] = json.loads(result.stdout)
    # The exit status follows the answer: 1 when it says success: false.
    assert result.exit_code == (0 if data.get("success", True) else 1), result.output
    return data


def printed(data: dict[str, Any]) -> tuple[float, ...]:
    """x, y, z, qx, qy, qz, qw of a pose as ``cadkg call`` prints it."""
    return (*data["position"].values(), *data["orientation"].values())


def turned(position: tuple[float, float, float], yaw_degrees: float) -> tuple[float, ...]:
    half = math.radians(yaw_degrees) / 2
    return (*position, 0.0, 0.0, math.sin(half), math.cos(half))


def test_both_guide_infos_print_j1_s_key(store: Path) -> None:
    table2 = call(store, "guide_info", "name=J1")
    assert (table2["success"], table2["id"], table2["frame"]) == (True, "ID0002", "robot_base")
    assert printed(table2["key_frame"]) == pytest.approx(turned((0.662, -0.305, 0.345), -90), abs=1e-12)
    reference = call(store, "CAD_platform.guide_info", "jig=J1", "guide=1")
    assert printed(reference["data"]["key_center_frame"]) == pytest.approx(printed(table2["key_frame"]))
    assert reference["data"]["jig_corner_frame"] is None


def test_the_cursor_of_each_client_is_kept_beside_the_store(store: Path) -> None:
    assert call(store, "CAD_platform.next_operation", "--client", "left")["type"] == "EC"
    assert call(store, "CAD_platform.next_operation", "--client", "left")["type"] == "PC"
    assert call(store, "CAD_platform.next_operation", "--client", "right")["type"] == "EC"
    third = call(store, "CAD_platform.next_operation", "--client", "left")
    assert (third["type"], third["label"], [s["jig"] for s in third["spot"]]) == (
        "RC",
        ["GR11"],
        ["J1", "J2", "J3"],
    )
    assert json.loads((store / "cursors.json").read_text())["cursors"]["elvez"]["left"] == {"position": 3}
    call(store, "CAD_platform.reset_sequence_list", "--client", "left")


def test_other_services_through_the_command_line(store: Path) -> None:
    assert call(store, "cable_info", "name=CA5")["con_index"] == [4, 0, 1, 0]
    assert call(store, "CAD_platform.cable_info", "label=CA5")["length"] == 620.0
    assert call(store, "CAD_platform.get_tools_service")["data"] == ["gun", "gripper"]
    missing = call(store, "con_info", "name=X1")
    assert missing["success"] is False and missing["message"].startswith("no connector 'X1'")


def test_services_validate_and_queries(store: Path) -> None:
    listed = run("services").stdout
    for name in ("guide_info", "index_op", "CAD_platform.all_operations", "CAD_platform.get_tools_service"):
        assert name in listed
    checked = run("validate", store)
    assert checked.exit_code == 0, checked.output
    result = run("query", store, "elvez-operations-at-spot", "label=J3", "--format", "rows-json")
    assert result.exit_code == 0, result.output
    assert [(r["order"], r["code"]) for r in json.loads(result.stdout)["rows"]] == [
        (3, "RC"),
        (4, "RC"),
        (8, "RC"),
        (9, "TJ"),
    ]


def test_meshes_and_frames_for_rviz(store: Path) -> None:
    with KnowledgeGraph.open(store) as kg:
        session = Session(kg.cell_model(), kg=kg)
        specs = {s.frame_id: s for s in element_meshes(session, kg.files_dir)}
        # The platform's by commercial code, C1's by CAD ID, the rest from their scene shapes.
        assert specs["ID0002platform"].mesh_uri.endswith("meshes/elvez/platform/0011.stl")
        assert specs["ID0006platform"].mesh_uri.endswith("meshes/elvez/platform/0030.stl")
        assert specs["ID0002combs"].mesh_uri.endswith("meshes/elvez/combs/ID0002.stl")
        assert specs["ID0003combs"].mesh_uri.endswith("meshes/elvez/combs/ID0003.stl")
        assert specs["ID000002ATC"].mesh_uri.endswith("meshes/elvez/ATC/ID000002.stl")
        for spec in specs.values():
            assert Path(spec.mesh_uri.removeprefix("file://")).stat().st_size > 84
        frames = {f.child: f for f in platform_frames(session)}
        assert frames["ID0002platformguide1"].parent == "ID0002platform"
        assert frames["ID0004platformtape_spot1"].pose.position[0] == pytest.approx(0.03)
        assert frames["ID0006platformtray2"].pose.position == pytest.approx((0.15, 0.075, 0.01))
        assert frames["ID000003ATC_ATC_base_gripper"].pose.position == pytest.approx((0.025, -0.045, 0.115))


def test_a_bad_file_fails_the_build_with_its_location(tmp_path: Path) -> None:
    cell = tmp_path / "cell"
    shutil.copytree(EXAMPLES / "elvez-cell", cell)
    sequence = cell / "Assembly_sequence.csv"
    sequence.write_bytes(sequence.read_bytes().replace(b"7;PC;", b"7;SC;"))
    result = run("build", cell / "manifest.toml", "--store", tmp_path / "store")
    assert result.exit_code == 2
    assert (
        "Assembly_sequence.csv:8: unknown operation code (found 'SC', expected EC, PC, RC, T, TJ)"
        in result.stderr
    )
    assert not (tmp_path / "store" / "CURRENT").exists()
