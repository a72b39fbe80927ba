"""The element definitions reader (Jigs_definition_v2.xml): every element, units, the order of
the angles, the quirks of real files, and located errors."""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable
from pathlib import Path

import pytest

from cadkg.errors import IngestError, IngestWarning
from cadkg.geometry.frames import quaternion_from_rpy
from cadkg.geometry.poses import Pose
from cadkg.usecases.elvez.files.definitions import looks_like_element_definitions, read_element_definitions
from cadkg.usecases.elvez.files.xml_fields import rotation_xyz
from tests.conftest import ROOT

Write = Callable[[str, str | bytes], Path]
EXAMPLE = ROOT / "examples" / "elvez-cell" / "Jigs_definition_v2.xml"


def pose(x: float = 0, y: float = 0, z: float = 0, r: float = 0, p: float = 0, yaw: float = 0) -> str:
    return (
        f'<pos name="x">{x}</pos><pos name="y">{y}</pos><pos name="z">{z}</pos>'
        f'<rot name="R">{r}</rot><rot name="P">{p}</rot><rot name="Y">{yaw}</rot>'
    )


KEY_SIZES = 'length="10" gap="8" height="30" height_corner="50" xcol1="0" xcol2="10" ycol1="-14" ycol2="24"'
KEY = f"<key {KEY_SIZES}>{pose(0, 8, 120)}</key>"
ONE = 'xdim="1" ydim="1" zdim="1"'
JIG = 'model="0011" xdim="10" xcol1="0" xcol2="10" ydim="24" ycol1="-8" ycol2="22" zdim="150"'


def data(*body: str) -> str:
    return '<?xml version="1.0"?>\n<data>\n' + "\n".join(body) + "\n</data>\n"


def test_the_example_definitions() -> None:
    definitions = {d.model: d for d in read_element_definitions(EXAMPLE)}
    assert [(d.kind, d.model) for d in definitions.values()] == [
        ("jig", "0011"),
        ("jig", "0012"),
        ("jig", "0015"),
        ("comb", "0000210"),
        ("box", "0030"),
        ("ATC_station", "0000301"),
        ("ATC_station", "0000302"),
    ]
    guide = definitions["0011"]
    assert guide.size == (0.01, 0.024, 0.15)
    assert guide.extents == (0.0, 0.01, -0.008, 0.022)
    assert (guide.centre, guide.footprint) == ((0.005, 0.012), (0.01, 0.036))
    (key_guide,) = guide.guides
    key = key_guide.key
    assert (key.length, key.gap, key.height, key.height_corner) == (0.01, 0.008, 0.03, 0.05)
    assert key.extents == (0.0, 0.01, -0.014, 0.024)
    assert key.corner == Pose((0.0, 0.008, 0.12))
    assert key_guide.collision is not None and key_guide.collision.size == (0.008, 0.02, 0.01)
    taping = definitions["0012"]
    assert [g.couple for g in taping.guides] == ["1", "2"]
    (spot,) = taping.tape_spots
    assert (spot.id, spot.guide, spot.size, spot.corner) == (
        "1",
        "1",
        (0.03, 0.04, 0.005),
        Pose((0.015, 0.0, 0.06)),
    )
    assert [t.id for t in definitions["0030"].trays] == ["1", "2"]
    assert definitions["0000210"].centre is None and definitions["0000210"].tape_spots == ()
    gun, gripper = definitions["0000301"].tool, definitions["0000302"].tool
    assert gun is not None and gripper is not None
    assert (gun.kind, gun.size, gun.fingers, gun.nail) == ("gun", (0.22, 0.3, 0.1), None, None)
    assert (gripper.kind, gripper.fingers) == ("gripper", (0.013, 0.034, 0.0153))
    assert gripper.nail == Pose((0.0, 0.0, 0.26))


def test_angles_turn_about_x_then_the_new_y_then_the_newest_z() -> None:
    # R = 90° then Y = 90°: Rx·Rz, not the fixed-axis roll-pitch-yaw Rz·Rx of REP 103.
    half = math.pi / 2
    assert rotation_xyz(half, 0.0, half).close_to(Pose(orientation=(0.5, -0.5, 0.5, 0.5)), 1e-12)
    assert not rotation_xyz(half, 0.0, half).close_to(
        Pose(orientation=quaternion_from_rpy(half, 0.0, half)), 1e-3
    )
    # One angle alone is the same in both orders.
    assert rotation_xyz(0.0, 0.3, 0.0).close_to(Pose(orientation=quaternion_from_rpy(0.0, 0.3, 0.0)), 1e-12)


def test_pose_children_in_any_order_and_comments(write: Write) -> None:
    shuffled = '<rot name="Y">0</rot><pos name="z">5</pos><!-- 112.5 --><rot name="R">0</rot>'
    shuffled += '<pos name="x">1</pos><rot name="P">0</rot><pos name="y">2</pos>'
    text = data(
        f'<jig {JIG}><!--Guide--><guide couple="1">{KEY}<collision {ONE}>{shuffled}</collision>',
        "</guide></jig>",
    )
    (definition,) = read_element_definitions(write("d.xml", text))
    collision = definition.guides[0].collision
    assert collision is not None and collision.corner == Pose((0.001, 0.002, 0.005))


def test_a_jig_without_centre_and_finger_length(write: Write) -> None:
    tool = pose(1, 2, 3)
    text = data(
        f'<jig {JIG}><guide couple="1">{KEY}</guide></jig>',
        '<ATC_station model="0000302" xdim="10" ydim="34" zdim="65" tool="gripper">',
        f"<tool_base>{tool}</tool_base><tool_end>{tool}</tool_end>",
        '<tool_dim x="73" y="25" z="265"></tool_dim>',
        '<finger_dim finger_length = "40.0" finger_width = "20.0" finger_height = "125.0"></finger_dim>',
        "</ATC_station>",
    )
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", IngestWarning)
        jig, station = read_element_definitions(write("d.xml", text))
    assert (jig.centre, jig.footprint, jig.guides[0].collision) == (None, None, None)
    assert station.tool is not None and station.tool.fingers == (0.04, 0.02, 0.125)
    assert [str(w.message).split(": ", 1)[1] for w in caught] == [
        "finger_length of <finger_dim> read as finger_thickness"
    ]


@pytest.mark.parametrize(
    ("body", "line", "reason"),
    [
        (
            f'<jig {JIG}><guide couple="1">{KEY}</guide></jig>\n<jig {JIG}/>',
            4,
            "model 0011 defined twice (first on line 3)",
        ),
        (
            f'<jig {JIG}>\n<guide couple="1">{KEY}</guide>\n<guide couple="1">{KEY}</guide></jig>',
            5,
            "guide couple 1 given twice (first on line 4)",
        ),
        (f'<jig {JIG}>\n<guide couple="1"/></jig>', 4, "<guide> has no <key>"),
        (f'<jig {JIG} colour="red"/>', 3, "unknown attribute 'colour' of <jig>"),
        ('<jig model="0011" xdim="10" ydim="24" zdim="150"/>', 3, "<jig> without a 'xcol1' attribute"),
        (f'<jig {JIG} xcenter="5"/>', 3, "<jig> without a 'ycenter' attribute"),
        ("<jig " + JIG.replace('ydim="24"', 'ydim="2,4"') + "/>", 3, "'ydim' of <jig> is not a number"),
        ("<tool/>", 3, "unexpected element <tool> inside <data>"),
        (
            f'<jig {JIG}><guide couple="1">\n<key {KEY_SIZES}><pos name="x">1</pos></key></guide></jig>',
            4,
            "<key> has no y, z, R, P, Y",
        ),
        (
            f'<jig {JIG}><guide couple="1">{KEY}</guide>\n'
            f'<tape_spot id="1" guide="2" {ONE}>{pose()}</tape_spot></jig>',
            4,
            "taping spot 1 names guide '2', which model 0011 does not define",
        ),
        (
            f'<box model="0030" {ONE}>\n<tray id="1" {ONE}>{pose()}</tray>\n'
            f'<tray id="1" {ONE}>{pose()}</tray></box>',
            5,
            "<tray> id 1 given twice (first on line 4)",
        ),
        (
            f'<ATC_station model="1" {ONE} tool="gun">\n<tool_base>{pose()}</tool_base></ATC_station>',
            3,
            "<ATC_station> has no <tool_end>",
        ),
    ],
)
def test_located_errors(write: Write, body: str, line: int, reason: str) -> None:
    with pytest.raises(IngestError) as info:
        read_element_definitions(write("bad.xml", data(body)))
    assert (info.value.line, info.value.reason) == (line, reason)


def test_entities_are_refused(write: Write) -> None:
    text = '<?xml version="1.0"?>\n<!DOCTYPE data [<!ENTITY e "x">]>\n<data/>\n'
    with pytest.raises(IngestError, match="<!DOCTYPE> is not allowed"):
        read_element_definitions(write("bad.xml", text))


@pytest.mark.parametrize(
    ("head", "claimed"),
    [
        (b'<?xml version="1.0"?>\n<data>\n    <jig model="0011">', True),
        (b"<data><!-- the boxes --><box model='1'>", True),
        (b"<data><ATC_station model='1'>", True),
        (b"<data><code>X</code></data>", False),
        (b"<data><wiring_harness id='1'>", False),
        (b"<jig model='1'/>", False),
    ],
)
def test_sniffing(head: bytes, claimed: bool) -> None:
    assert looks_like_element_definitions(head) is claimed
