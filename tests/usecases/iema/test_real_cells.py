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
import math
import os
import shutil
import subprocess
import warnings
from pathlib import Path
from typing import Any

import pytest

from cadkg.geometry.poses import Pose
from cadkg.graph import KnowledgeGraph
from cadkg.ingest.wri import read_wri
from cadkg.query.validate import validate
from cadkg.services.session import Session
from cadkg.services.table import call
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
    # The components' codes are digits only: nothing stripped. The ducts' (BOCCH.60X60G, as the
    # real tables write them) lose their point in the node's ID dictionary, so the node meets no
    # model for them and leaves them out of its components, as on the real cabinets.
    ducts = {cad: code for cad, code in coded.items() if code.startswith("BOCCH.")}
    assert len(ducts) == 9
    assert {cad: node["products"][cad] for cad in coded} == {
        cad: code.replace(".", "") if cad in ducts else code for cad, code in coded.items()
    }
    parts = {code for cad, code in coded.items() if cad not in ducts}
    assert parts <= set(node["models"]) and not {node["products"][cad] for cad in ducts} & set(node["models"])
    models = {m.key for m in read_component_models(EXAMPLE / "components.xml")}
    # cadkg keeps the code as written: the ducts meet their models, but CN8's (BOCCH.25X30G) has none.
    assert set(coded.values()) - models == {"BOCCH.25X30G"}
    assert len({row.label for row in rows if row.commercial}) == 62


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


# -- the node's start on the example, its pose services beside cadkg's -----------------------
# The node's own script runs as it is under a Python 2.7 with numpy, enum34, xmltodict and
# pyexcel-ods, in a temporary folder, only ROS and PyKDL stubbed (tests/usecases/iema/reference_node.py).
# Its files are the example's, under the names the launch files give them.
NODE_FILES = {
    "QE01_cad.x3d": "QE01_cad.x3d",
    "QE01_ids.wri": "ids.wri",
    "components.xml": "components.xml",
    "lista-cablaggio.csv": "lista-cablaggio.csv",
    "schema-morsetti.ods": "schema-morsetti.ods",
}
LAUNCH = {
    "demo_type": "wires",
    "output_stl": False,
    "gearbox_display": True,
    "cad_name": "QE01",
    "component_file": "components.xml",
    "wiring_file": "lista-cablaggio.csv",
    "terminal_file": "schema-morsetti.ods",
    "terminal_sheet": "QE01_Schema_Morsetti_00",
}
# The launch file's world → gearbox_rf: the cabinet frame, so both answer in it. The node's
# scene is z up (QE01_cad.x3d): the cabinet frame is its root turned -90° about x.
GEARBOX_RF = [[0.0, 0.0, 0.0], [-math.sqrt(0.5), 0.0, 0.0, math.sqrt(0.5)]]
# Equal: within 1 mm and 2 mrad. The node turns its scene back by 1.57 rad, not π/2
# (SceneConfiguration), which moves a point at the top of the plate by 0.8 mm.
METRE, RADIAN = 1e-3, 2e-3


def _modules_missing() -> str:
    if not PYTHON2 or not NODE_SCRIPTS.is_dir():
        return "no Python 2.7 or no node scripts"
    check = "import numpy, enum, xmltodict, pyexcel_ods"
    run = subprocess.run([PYTHON2, "-c", check], capture_output=True, timeout=120, check=False)
    return "" if run.returncode == 0 else "the Python 2.7 lacks numpy, enum34, xmltodict or pyexcel-ods"


NODE_START_SKIP = _modules_missing() if DATA else "no node"


def _node_start(tmp_path: Path, requests: list[tuple[str, str, dict[str, Any]]]) -> dict[str, Any]:
    from tests.usecases.iema.reference_node import DRIVER, stub_files

    stubs, cell = tmp_path / "node-stubs", tmp_path / "node-cell"
    for name, text in stub_files(str(NODE_SCRIPTS.parent)).items():
        (stubs / name).parent.mkdir(parents=True, exist_ok=True)
        (stubs / name).write_text(text, encoding="utf-8")
    cell.mkdir()
    for name, source in NODE_FILES.items():
        shutil.copyfile(EXAMPLE / source, cell / name)
    plan = tmp_path / "node-plan.json"
    params = dict(LAUNCH, files_path=str(cell) + os.sep)
    plan.write_text(json.dumps({"params": params, "gearbox_rf": GEARBOX_RF, "requests": requests}))
    driver = tmp_path / "node-driver.py"
    driver.write_text(DRIVER, encoding="utf-8")
    run = subprocess.run(
        [PYTHON2, "-B", str(driver), str(stubs), str(NODE_SCRIPTS), str(plan)],
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    assert run.returncode == 0, run.stderr[-2000:]
    assert "database_ready" in run.stdout.splitlines()
    started: dict[str, Any] = json.loads(run.stdout.splitlines()[-1])
    return started


def _node_pose(pose: dict[str, Any]) -> tuple[tuple[float, ...], tuple[float, ...]]:
    p, q = pose["position"], pose["orientation"]
    return (p["x"], p["y"], p["z"]), (q["x"], q["y"], q["z"], q["w"])


def _gap(node: tuple[tuple[float, ...], tuple[float, ...]], ours: Any) -> tuple[float, float]:
    """Distance (m) and angle (rad) between the node's pose and cadkg's."""
    distance = math.dist(node[0], ours.position)
    dot = abs(sum(a * b for a, b in zip(node[1], ours.orientation, strict=True)))
    norm = math.sqrt(sum(a * a for a in node[1]))
    return distance, 2 * math.acos(min(1.0, dot / norm))


def _pose_pairs(tmp_path: Path) -> tuple[list[tuple[str, str, str, Any, Any]], list[str], list[Any]]:
    """(service, key, field, the node's pose, cadkg's pose) for every pose both answer, and what
    the node answers with an error or without a pose cadkg gives."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        kg = KnowledgeGraph.build(EXAMPLE / "manifest-node.toml")
    with kg:
        model = kg.cell_model()
        session = Session(model)
        ducts = {d for step in model.steps for d in step.ducts}
        labels = sorted(
            label
            for label, g in model.components.items()
            if g.target is not None
            and label not in ducts
            and not label.startswith("RAIL")
            and not g.terminal_block
        )
        strips = sorted(label for label, g in model.components.items() if g.terminal_block)
        ours: list[tuple[str, str, dict[str, Any]]] = []
        requests: list[tuple[str, str, dict[str, Any]]] = []
        for label in labels:
            ours.append(("cad_service", label, {"label": label}))
            requests.append(("cad_service", "cad_data", {"label": label.replace("-", "")}))
        for label in strips:
            ours.append(("get_terminal_data", label, {"label": label}))
            requests.append(("get_terminal_data", "terminal_data", {"label": label}))
        # Each wire from its own position: a service that fails leaves the node's cursor where it is.
        for position in range(110):
            requests.append(("reset_to_connection_list", "DataSrv", {"data": position, "source": "orig"}))
            requests.append(("group_connection_provider", "connection_group", {}))
            requests.append(("reset_to_connection_list", "DataSrv", {"data": position, "source": "orig"}))
            requests += [("full_connection_provider", "connection_data", {})] * 2
        detected = call(session, "cad_service", {"label": "F1500.1"}).target_pose
        moved = Pose((detected.position[0] + 0.01, *detected.position[1:]), detected.orientation)
        pose = {
            "position": dict(zip("xyz", moved.position, strict=True)),
            "orientation": dict(zip("xyzw", moved.orientation, strict=True)),
        }
        requests.append(("get_item_screw_targets", "pin_data", {"label": "F1500.1", "cad_pose": pose}))
        node = _node_start(tmp_path, requests)["answers"]
        pairs: list[tuple[str, str, str, Any, Any]] = []
        lacking: list[str] = []

        def pair(service: str, key: str, field: str, theirs: dict[str, Any] | None, mine: Any) -> None:
            if mine is None:
                return
            # A pose the node leaves unfilled keeps ROS's default, a zero quaternion.
            if theirs is None or not any(theirs["orientation"].values()):
                lacking.append(f"{service} {key} {field}")
            else:
                pairs.append((service, key, field, _node_pose(theirs), mine))

        answers = iter(node)
        for service, key, params in ours:
            status, answer = next(answers)
            mine = call(session, service, params)
            if status != "ok":
                lacking.append(f"{service} {key}: {answer}")
                continue
            if service == "cad_service":
                pair(service, key, "target", answer["target_pose"], mine.target_pose)
                pair(service, key, "corner", answer["corner_pose"], mine.corner_pose)
                theirs = {p["pin"]: p for p in answer["pins"]}
                for pin in mine.pins:
                    for field in ("screw", "hole"):
                        given = theirs.get(pin.pin)
                        pair(
                            service,
                            f"{key}:{pin.pin}",
                            field,
                            given and given[field + "_pose"],
                            getattr(pin, field),
                        )
            else:
                pair(service, key, "terminal_start", answer["terminal_start"], mine.terminal_start)
                # The node appends each pin's screw and then its hole to `screws`.
                theirs = {
                    pin: (answer["screws"][2 * i], answer["screws"][2 * i + 1])
                    for i, pin in enumerate(answer["pins"])
                }
                for pin, screw, hole in zip(mine.pins, mine.screws, mine.holes, strict=True):
                    given = theirs.get(pin)
                    pair(service, f"{key}:{pin}", "screw", given and given[0], screw)
                    pair(service, f"{key}:{pin}", "hole", given and given[1], hole)
        groups, ends = [], []
        for position in range(110):
            next(answers)
            status, answer = next(answers)
            if status == "ok":
                groups.append(answer)
            else:
                lacking.append(f"group_connection_provider {position}: {answer}")
            next(answers)
            for source in ("orig", "dest"):
                status, answer = next(answers)
                if status == "ok":
                    ends.append(answer)
                else:
                    lacking.append(f"full_connection_provider {position} {source}: {answer}")
        screw_targets = next(answers)[1]
        by_position = {g["list_position"]: g for g in groups}
        keypoints: list[tuple[str, Any, Any]] = []
        cursors.reset_connection_list(session)
        while not (w := cursors.group_connection_provider(session)).end:
            if w.list_position not in by_position:
                continue
            theirs = by_position[w.list_position]
            for end, mine in (("origin", w.origin), ("destination", w.destination)):
                key = f"{w.list_position} {end} {mine.label}"
                assert mine is not None
                pair(
                    "group_connection_provider",
                    key,
                    "component_pose",
                    theirs[end]["component_pose"],
                    mine.component_pose,
                )
                pair("group_connection_provider", key, "screw", theirs[end]["screw_pose"], mine.screw)
                pair("group_connection_provider", key, "hole", theirs[end]["hole_pose"], mine.hole)
            keypoints.append((str(w.list_position), theirs["path_keypoints"], w.path_keypoints))
        by_end = {(e["list_position"], e["source"]): e for e in ends if not e["end"]}
        cursors.reset_connection_list(session)
        while not (e := cursors.full_connection_provider(session)).end:
            if (e.list_position, e.source) in by_end:
                given = by_end[(e.list_position, e.source)]
                pose = None if given["missing_pin_data"] else given["component_pose"]
                pair(
                    "full_connection_provider",
                    f"{e.list_position} {e.source} {e.label}",
                    "component_pose",
                    pose,
                    e.component_pose,
                )
        mine = call(session, "get_item_screw_targets", {"label": "F1500.1", "cad_pose": moved})
        theirs = dict(
            zip(
                screw_targets["pins"],
                zip(screw_targets["screws"], screw_targets["holes"], strict=True),
                strict=True,
            )
        )
        for pin, screw, hole in zip(mine.pins, mine.screws, mine.holes, strict=True):
            pair("get_item_screw_targets", f"F1500.1:{pin}", "screw", theirs[pin][0], screw)
            pair("get_item_screw_targets", f"F1500.1:{pin}", "hole", theirs[pin][1], hole)
    return pairs, lacking, keypoints


# Where the node's poses differ from cadkg's, by label (docs/iema-services.md, "The node's
# start on the example"): the differences of "Differences from the reference node", seen.
DIFFERING = {
    "A0080.1": "corner: the node never reads a model's corner item",
    "B0040.3": "turned 180°: the node's target keeps the cabinet's orientation, its corner and pins unturned",
    "SSB-10Q1": "turned +90°: as B0040.3",
    "SSB-33CAM1": "turned 180°: as B0040.3",
    "E0040.1": "several items: the node measures the root item only (target, corner)",
    "H0050.1": "several items: target",
    "Q0010": "several items: target",
    "S0050.1": "several items: target",
    "SSB-08H1": "several items: target, corner",
    "SSB-10F1": "several items: target",
    "SSB-10KA1": "several items: target",
    "SSB-10KA2": "several items: target",
    "SSB-10KA3": "several items: target",
    "SSB-75G2": "several items: target, corner",
    **{f"F1500.{n}": "several items: target, and the detected pose's shift follows it" for n in (1, 2, 3)},
    **{f"Q1500.{n}": "several items: target" for n in (1, 2, 3)},
    **{
        strip: "terminal strip: the providers' component_pose is the first item's target moved half the strip"
        for strip in ("X0030.1", "X0030.2", "X0031", "X1500", "X1600", "X1700")
    },
}


@pytest.mark.skipif(bool(NODE_START_SKIP), reason=NODE_START_SKIP or "-")
def test_the_node_starts_on_the_example_and_its_poses_are_cadkgs(tmp_path: Path) -> None:
    pairs, lacking, _ = _pose_pairs(tmp_path)
    gaps = [(service, key, field, *_gap(node, ours)) for service, key, field, node, ours in pairs]
    equal = [g for g in gaps if g[3] <= METRE and g[4] <= RADIAN]
    assert (len(gaps), len(equal)) == (1394, 1059)
    assert max(g[3] for g in equal) < 2e-4 and max(g[4] for g in equal) < 8e-4
    differing = {g[1].split(":")[0].split()[-1] for g in gaps if g not in equal}
    assert differing == set(DIFFERING)
    # Every terminal strip's start, screws and holes are the node's (get_terminal_data).
    assert all(g in equal for g in gaps if g[0] == "get_terminal_data")
    # What only cadkg answers: the relays' pins of parts management, the second root model's and
    # the second child's pins, the root item 1; the node's group provider fails on those pins.
    unanswered = {
        line.split(":")[0].split()[1].rstrip(":") for line in lacking if line.startswith("cad_service")
    }
    assert unanswered == {"1", "K1510.1", "K1510.2", "K1510.3", "SSB-08H1", "SSB-10F1"}
    failing = sorted(
        int(line.split()[1].rstrip(":")) for line in lacking if "KeyError" in line and "group" in line
    )
    assert failing == [91, 92, 93, 94, 95, 96, 105, 107]
