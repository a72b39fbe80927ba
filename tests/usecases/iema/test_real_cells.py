"""The three real cabinets of the reference IEMA node, when a local copy is given.

The node's package has no licence, so its files are not in this repository: set
``CADKG_IEMA_CELLS`` to a local copy of its ``data`` folder (the one holding ``gearbox_zero``,
``gearbox_demo`` and ``remodel``) to run these tests. Each cabinet is built from its ID table and
one connection list; the counts and first wires are those recorded in
docs/formats/iema-real-files.md, the node's own answers on the same files. With a Python 2.7
(``CADKG_PYTHON2``, else ``python2.7``), the node's own list and ID-table readers run on these
lists and on the example's, and every field they give is compared with cadkg's providers
(docs/iema-services.md, "The node's readers on the same files").
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import warnings
from pathlib import Path
from typing import Any

import pytest

from cadkg.graph import KnowledgeGraph
from cadkg.ingest.wri import read_wri
from cadkg.query.validate import validate
from cadkg.services.session import Session
from cadkg.usecases.iema import cursors
from cadkg.usecases.iema.component_model import read_component_models
from tests.changes.test_derived_things import check_derived
from tests.conftest import ROOT

DATA = os.environ.get("CADKG_IEMA_CELLS", "")
pytestmark = pytest.mark.skipif(not DATA, reason="CADKG_IEMA_CELLS names no local copy of the real cabinets")

ZERO_LIST = "PROGETTO WIRES_244_IEMA_HILL_Lista_cablaggio"
# cabinet, ID table, connection list → wires the providers serve, wires given to people,
# the first wire (position, origin, destination, number, duct path as written).
CASES = {
    "gearbox_zero csv": (
        "gearbox_zero",
        "gearbox00001_ids.wri",
        ZERO_LIST + ".csv",
        52,
        19,
        (0, "F1500.1:1", "F1500.2:1", "0005L1", "=-U4"),
    ),
    "gearbox_zero xlsx": (
        "gearbox_zero",
        "gearbox00001_ids.wri",
        ZERO_LIST + ".xlsx",
        52,
        19,
        (0, "F1500.1:1", "F1500.2:1", "0005L1", "=-U4"),
    ),
    "gearbox_demo": (
        "gearbox_demo",
        "gearbox_demo_ids.wri",
        "cablaggio.csv",
        50,
        0,
        (0, "F1500.1:14", "Q1500.1:A1", "1500.51", "=-CN2'=-CN3'=-CN5"),
    ),
    "remodel": (
        "remodel",
        "Q1_simplified_ids.wri",
        "TEST1_REMODEL_KOMAX.csv",
        122,
        0,
        (0, "X0V:1:a2", "10F1:X4:A2", "0V", "=-CN2;=-CN3;=-CN4"),
    ),
}


def _build(tmp_path: Path, cabinet: str, ids: str, wiring: str, folder: Path | None = None) -> KnowledgeGraph:
    folder = folder or Path(DATA) / cabinet
    manifest = tmp_path / "manifest.toml"
    lines = ["[cell]", f'name = "{cabinet}"', 'profile = "iema"', 'base_iri = "https://example.org/real/"']
    for name in (ids, wiring):
        lines += ["", "[[source]]", f"path = {str(folder / name)!r}"]
    manifest.write_text("\n".join(lines) + "\n", encoding="utf-8")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return KnowledgeGraph.build(manifest)


# -- the node's own list reader beside cadkg's providers --------------------------------------
# The node's scripts sit beside its data folder; its list and ID-table readers are run as they
# are with a Python 2.7, only the modules of ROS and of unused readers stubbed.
NODE_SCRIPTS = Path(DATA).parent / "scripts" if DATA else Path()


def _python2() -> str:
    """``CADKG_PYTHON2`` as given, else a ``python2.7`` on the path that runs (a version
    manager's shim may stand there without a Python 2.7 behind it), else ""."""
    given = os.environ.get("CADKG_PYTHON2")
    if given:
        return given
    found = shutil.which("python2.7")
    if found is None:
        return ""
    runs = subprocess.run([found, "-c", "pass"], capture_output=True, timeout=60, check=False)
    return found if runs.returncode == 0 else ""


PYTHON2 = _python2()
EXAMPLE = ROOT / "examples" / "iema-switchgear"
STUBS = {
    "rospy.py": "# ROS stub: the readers run outside ROS\n",
    # Frames that hold nothing: of the model dictionary only its keys are compared.
    "PyKDL.py": (
        "class Vector(object):\n    def __init__(self, *xyz):\n        self.xyz = xyz\n"
        "class Rotation(object):\n    def DoRotX(self, angle):\n        pass\n    DoRotY = DoRotZ = DoRotX\n"
        "class Frame(object):\n    def __init__(self):\n        self.p, self.M = Vector(), Rotation()\n"
    ),
    # The models' attributes, which is all the node takes from this parse.
    "xmltodict.py": (
        "import xml.etree.ElementTree as ET\n"
        "def parse(text):\n"
        "    codes = [dict(('@' + k, v) for k, v in c.attrib.items()) for c in ET.fromstring(text)]\n"
        "    return {'data': {'code': codes}}\n"
    ),
    "pyexcel_ods.py": "def get_data(*args, **kwargs):\n    raise NotImplementedError\n",
}
DRIVER = """
import json, sys
sys.path[:0] = [sys.argv[1], sys.argv[2]]
from database_wiress.partdb.data_dictionaries import GearboxPartsData
def ends(c):
    return [c['orig']['part_label'], c['orig']['pin'], c['dest']['part_label'], c['dest']['pin']]
wires = [[i] + ends(c) + [c['wire'], c['path']]
         for i, c in enumerate(GearboxPartsData._createConnectionList(sys.argv[3]))]
board = GearboxPartsData._createBoardDict(sys.argv[4])
out = {'wires': wires, 'labels': dict((k, v['label']) for k, v in board.items())}
out['products'] = dict((k, v['product']) for k, v in board.items())
if len(sys.argv) > 5:
    out['models'] = sorted(GearboxPartsData._generateComponentDict(sys.argv[5]))
print(json.dumps(out))
"""
WIRE_FIELDS = (
    "list_position",
    "origin.label",
    "origin.pin",
    "destination.label",
    "destination.pin",
    "wire",
    "wire_path",
)
# cell → (manifest or None for a cabinet of DATA, ID table, connection list)
NODE_CASES = {
    "example": (None, EXAMPLE / "ids.wri", EXAMPLE / "lista-cablaggio.csv"),
    "gearbox_zero": ("gearbox_zero", Path("gearbox00001_ids.wri"), Path(ZERO_LIST + ".csv")),
    "gearbox_demo": ("gearbox_demo", Path("gearbox_demo_ids.wri"), Path("cablaggio.csv")),
    "remodel": ("remodel", Path("Q1_simplified_ids.wri"), Path("TEST1_REMODEL_KOMAX.csv")),
}


def _node_answers(tmp_path: Path, ids: Path, wiring: Path, models: Path | None = None) -> dict[str, Any]:
    stubs = tmp_path / "stubs"
    stubs.mkdir()
    for name, text in STUBS.items():
        (stubs / name).write_text(text, encoding="utf-8")
    driver = tmp_path / "driver.py"
    driver.write_text(DRIVER, encoding="utf-8")
    # -B: no bytecode is written into the node's checkout.
    run = subprocess.run(
        [PYTHON2, "-B", str(driver), str(stubs), str(NODE_SCRIPTS), str(wiring), str(ids)]
        + ([str(models)] if models else []),
        capture_output=True,
        text=True,
        timeout=600,
        check=True,
    )
    answers: dict[str, Any] = json.loads(run.stdout.splitlines()[-1])
    return answers


def _differences(
    node: list[list[object]], ours: list[list[object]]
) -> list[tuple[object, str, object, object]]:
    return [
        (mine[0], field, theirs[i], mine[i])
        for theirs, mine in zip(node, ours, strict=True)
        for i, field in enumerate(WIRE_FIELDS)
        if theirs[i] != mine[i]
    ]


@pytest.mark.skipif(not PYTHON2 or not NODE_SCRIPTS.is_dir(), reason="no Python 2.7 or no node scripts")
@pytest.mark.parametrize("case", sorted(NODE_CASES))
def test_the_nodes_reader_and_cadkg_serve_the_same_wires(tmp_path: Path, case: str) -> None:
    cabinet, ids, wiring = NODE_CASES[case]
    if cabinet is not None:
        ids, wiring = Path(DATA) / cabinet / ids, Path(DATA) / cabinet / wiring
    node = _node_answers(tmp_path, ids, wiring)
    with _build(tmp_path, ids.parent.name, ids.name, wiring.name, folder=ids.parent) as kg:
        session = Session(kg.cell_model())
        ours = []
        while not (w := cursors.group_connection_provider(session)).end:
            assert w.origin is not None and w.destination is not None
            ends = [w.origin.label, w.origin.pin, w.destination.label, w.destination.pin]
            ours.append([w.list_position, *ends, w.wire, w.wire_path])
    # The node keeps a label's function part (=SSB-05U2 → SSB05U2); cadkg keys the device (05U2).
    items = {row.cad_id: (row.raw_label.split("-")[0] + row.label).lstrip("=") for row in read_wri(ids)}
    assert len(node["wires"]) == len(ours)
    # The node deletes every "-" of a label (SSB-10F1 → SSB10F1); cadkg keeps the label's own.
    differing = [d for d in _differences(node["wires"], ours) if d[2] != str(d[3]).replace("-", "")]
    assert differing == []
    assert {k: v for k, v in node["labels"].items() if v != items[k].replace("-", "")} == {}
    hyphens = {v for row in ours for v in (row[1], row[3]) if "-" in str(v)}
    assert len(_differences(node["wires"], ours)) == sum(
        (row[1] in hyphens) + (row[3] in hyphens) for row in ours
    )


@pytest.mark.skipif(not PYTHON2 or not NODE_SCRIPTS.is_dir(), reason="no Python 2.7 or no node scripts")
def test_the_nodes_dictionaries_meet_every_example_label_with_its_model(tmp_path: Path) -> None:
    # The node's cabling handler looks every scene item up in its ID dictionary, then the
    # item's code in its model dictionary: no row may be dropped, no code go unmatched.
    node = _node_answers(
        tmp_path, EXAMPLE / "ids.wri", EXAMPLE / "lista-cablaggio.csv", EXAMPLE / "components.xml"
    )
    rows = read_wri(EXAMPLE / "ids.wri")
    assert set(node["labels"]) == {row.cad_id for row in rows}
    coded = {row.cad_id: row.commercial for row in rows if row.commercial}
    assert {cad: node["products"][cad] for cad in coded} == coded  # digits only: nothing stripped
    assert set(coded.values()) <= set(node["models"])
    assert set(coded.values()) <= {m.key for m in read_component_models(EXAMPLE / "components.xml")}
    assert len({row.label for row in rows if row.commercial}) == 61


@pytest.mark.parametrize("case", sorted(CASES))
def test_the_providers_serve_the_nodes_wires(tmp_path: Path, case: str) -> None:
    cabinet, ids, wiring, served, for_people, first = CASES[case]
    with _build(tmp_path, cabinet, ids, wiring) as kg:
        session = Session(kg.cell_model())
        wires = []
        while not (wire := cursors.group_connection_provider(session)).end:
            wires.append(wire)
        assert len(wires) == served
        assert [w.list_position for w in wires] == list(range(served))
        head = wires[0]
        assert head.origin is not None and head.destination is not None
        assert (
            head.list_position,
            f"{head.origin.label}:{head.origin.pin}",
            f"{head.destination.label}:{head.destination.pin}",
            head.wire,
            head.wire_path,
        ) == first
        people = [f for f in validate(kg, shacl=False) if f.check == "wire-for-a-person"]
        assert len(people) == for_people


def test_the_name_error_row_keeps_wire_0005pe(tmp_path: Path) -> None:
    # The workbook shows #NAME? where the CSV has =-Stop:stop: the wire stays, its end flagged.
    with _build(tmp_path, "gearbox_zero", "gearbox00001_ids.wri", ZERO_LIST + ".xlsx") as kg:
        session = Session(kg.cell_model())
        assert cursors.reset_to_connection_list(session, 51).success
        wire = cursors.group_connection_provider(session)
        # Without a scene every end lacks data; the lost destination is the unknown end ?:?.
        assert wire.wire == "0005PE" and wire.missing_pin_data.split(", ")[-1] == "?:?"
        lost = [f for f in validate(kg, shacl=False) if f.check == "lost-wire-end"]
        assert [f.message for f in lost] == [
            "wire 0005PE: the list gives no reference for its destination; it is kept with missing pin data"
        ]


def test_the_plan_gives_the_robot_the_wires_the_node_serves(tmp_path: Path) -> None:
    # Under the default rules the robot gets the 52 wires of zones Q/QE, as the node serves them.
    from cadkg.plan.cell import plan_cell

    with _build(tmp_path, "gearbox_zero", "gearbox00001_ids.wri", ZERO_LIST + ".csv") as kg:
        plan = plan_cell(kg)
        robot = sorted(s.task.position for s in plan.steps if s.decision.performer == "robot")
        served = sorted(s.position for s in kg.cell_model().steps if s.performer == "robot")
        assert len(plan.steps) == 71 and robot == served and len(robot) == 52
        people = {s.decision.rule for s in plan.steps if s.decision.performer == "human"}
        assert people == {"zone"}
        assert (plan.files.tool_changes, plan.measure.tool_changes, plan.lower_bound) == (57, 35, 30)
        assert plan.files.violations == plan.measure.violations == 0


@pytest.mark.parametrize("case", sorted(CASES))
def test_the_diff_reads_the_models_wires_as_its_queries_find_them(tmp_path: Path, case: str) -> None:
    cabinet, ids, wiring, *_ = CASES[case]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        kg = _build(tmp_path, cabinet, ids, wiring)
    check_derived(kg)
