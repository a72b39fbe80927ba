"""The two real cells of the reference CAD platform package, when a local copy is given.

The package has no licence, so its files are not in this repository: set ``CADKG_ELVEZ_CELLS``
to a local copy of its folder (the one holding ``data_case1``, ``data_case2`` and ``launch``) to
run these tests. A manifest naming only the cell's files and its STL meshes, with the launch
file's three frames, is written beside a copy of each cell; the counts are those recorded in
docs/elvez-services.md.
"""

from __future__ import annotations

import os
import shutil
import warnings
from pathlib import Path

import pytest

from cadkg.graph import KnowledgeGraph
from cadkg.query.validate import validate
from cadkg.services.session import Session
from cadkg.services.table import call, services_for
from cadkg.usecases.elvez.model import build_model

PACKAGE = os.environ.get("CADKG_ELVEZ_CELLS", "")
pytestmark = pytest.mark.skipif(not PACKAGE, reason="CADKG_ELVEZ_CELLS names no local copy of the real cells")

FILES = (
    ("platform_cad.x3d", "platform_rf"),
    ("platform_ids.wri", None),
    ("combs_cad.x3d", "combs_rf"),
    ("combs_ids.wri", None),
    ("ATC_cad.x3d", "ATC_rf"),
    ("ATC_ids.wri", None),
    ("Jigs_definition_v2.xml", None),
    ("WH_configuration.xml", None),
    ("Components_definition.csv", None),
    ("Assembly_sequence.csv", None),
)
# The launch file's static transforms: x y z, then roll, pitch, yaw (it writes yaw first).
FRAMES = (
    ("platform_rf", (-0.486, 0.6601, 0.7186), (0.0, 0.0, 0.0)),
    ("combs_rf", (-0.7865, 0.083, 1.581), (0.0, 0.0, 0.0)),
    ("ATC_rf", (-1.54, 0.805, 1.4625), (1.57, 0.0, -1.57)),
)
# Meshes the reference loads: platform by commercial code (case 1) or CAD ID (case 2), combs and
# ATC by CAD ID; alternatives and old versions are left out.
MESHES = {
    "data_case1": ["platform/" + c for c in ("0001", "0011", "0014", "0015", "0016", "0020")],
    "data_case2": ["platform/ID00" + c for c in ("01", "02", "03", "04", "05", "06", "07", "09", "10", "20")],
}
COMMON = ["combs/ID000" + c for c in "1234"] + ["ATC/ID00000" + c for c in "1234"]


def manifest(cell: Path, case: str) -> Path:
    lines = ["[cell]", f'name = "{case}"', 'profile = "elvez"', f'base_iri = "https://example.org/{case}/"']
    for name, frame in FILES:
        lines += ["", "[[source]]", f'path = "{name}"'] + ([f'frame = "{frame}"'] if frame else [])
    for mesh in MESHES[case] + COMMON:
        lines += ["", "[[source]]", f'path = "stl/{mesh}.STL"']
    for child, xyz, rpy in FRAMES:
        lines += [
            "",
            "[[frame]]",
            'parent = "cell"',
            f'child = "{child}"',
            f"xyz = {list(xyz)}",
            f"rpy = {list(rpy)}",
        ]
    path = cell / "manifest.toml"
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.fixture(scope="module", params=["data_case1", "data_case2"])
def cell(
    request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory
) -> tuple[str, KnowledgeGraph]:
    case = str(request.param)
    target = tmp_path_factory.mktemp(case) / case
    shutil.copytree(Path(PACKAGE) / case, target)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return case, KnowledgeGraph.build(manifest(target, case))


def test_the_real_cell_builds_and_every_service_answers(cell: tuple[str, KnowledgeGraph]) -> None:
    case, kg = cell
    model = build_model(kg)
    first = case == "data_case1"
    assert len([e for e in model.elements if e.type == "jig"]) == (11 if first else 9)
    assert sum(len(e.cables) for h in model.harnesses for e in h.end_connectors) == (22 if first else 11)
    assert len(model.sequence) == (11 if first else 8)
    session = Session(kg.cell_model(), kg=kg)
    tool = model.tools()[0].tool
    params = {
        "guide_info": {"name": "J1.1"}, "cable_info": {"name": "CA1"}, "con_info": {"name": "WH1"},
        "wh_info": {"number": "1"}, "tool_info": {"name": tool}, "index_op": {"index": "1"},
        "wh_routes": {"number": "1"}, "CAD_platform.connector_info": {"label": "WH1"},
        "CAD_platform.cable_info": {"label": "CA1"}, "CAD_platform.jig_info": {"jig": "J1"},
        "CAD_platform.guide_info": {"jig": "J1", "guide": "1"}, "CAD_platform.tool_info": {"name": tool},
        "CAD_platform.reset_sequence_list_to": {"index": "2"}, "CAD_platform.index_operation": {"index": "0"},
    }  # fmt: skip
    failing = {
        "CAD_platform.tray_info": {"box": "B3", "tray": "1"},
        "CAD_platform.taping_spot_info": {"jig": "J1", "spot": "1"},
    }
    for service in services_for("elvez"):
        result = call(session, service.name, failing.get(service.name) or params.get(service.name, {}))
        assert result.success is (service.name not in failing), (service.name, result.message)
    assert len(call(session, "CAD_platform.all_guides", {}).data) == (11 if first else 9)
    assert len(call(session, "CAD_platform.get_tools_service", {}).data) == 3


def test_the_gaps_are_found_at_their_lines(cell: tuple[str, KnowledgeGraph]) -> None:
    case, kg = cell
    errors = sorted(
        f.location for f in validate(kg, shacl=False) if f.check == "elvez" and f.severity == "error"
    )
    trays = ["WH_configuration.xml:19", "WH_configuration.xml:3"]
    if case == "data_case1":
        assert errors == ["WH_configuration.xml:19", "WH_configuration.xml:3", "WH_configuration.xml:36"]
    else:
        assert errors == [f"Assembly_sequence.csv:{line}" for line in (6, 7, 8)] + trays


def test_the_real_sequences_are_checked_and_planned(cell: tuple[str, KnowledgeGraph]) -> None:
    from cadkg.plan.cell import plan_cell

    case, kg = cell
    order = [f for f in validate(kg, shacl=False) if f.check == "elvez-order"]
    plan = plan_cell(kg)
    assert [f for f in order if f.severity == "error"] == [] and plan.measure.violations == 0
    people = [s.task.label for s in plan.steps if s.decision.performer == "human"]
    if case == "data_case1":
        assert order == [] and people == []
        assert plan.files.tool_changes == plan.measure.tool_changes == plan.lower_bound == 0
    else:
        # WH3 is in no harness of the configuration, and WH2's branch is never routed
        assert people == ["EC WH3", "PC WH3", "RC WH3"]
        assert [f.message for f in order] == ["branch GR21 of WH2 is not routed by the sequence"]
        assert plan.files.tool_changes == plan.measure.tool_changes == plan.lower_bound == 1
