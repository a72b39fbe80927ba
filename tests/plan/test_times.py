"""The time model and the two lanes on hand-made tasks whose times are worked by hand."""

from __future__ import annotations

import pytest

from cadkg.plan.rules import RulesError, parse_rules
from cadkg.plan.tasks import Precedence, Task
from cadkg.plan.times import Lanes, TimeModel

MODEL = TimeModel(
    robot_speed_m_s=0.25,
    robot_tool_change_s=10,
    robot_task_s=60,
    person_task_s=240,
    robot_class_s={"screw": 80, "spring": 40},
    person_class_s={"spring": 200},
)


def test_a_task_takes_the_mean_of_its_classes_and_its_inside_tool_changes() -> None:
    screw = Task("A", "A", "wire", 0, ("screwdriver", "screwdriver"), classes=("screw", "screw"))
    mixed = Task("B", "B", "wire", 1, ("spring-opener", "screwdriver"), classes=("spring", "screw"))
    unlisted = Task("C", "C", "wire", 2, ("screwdriver",), classes=("", "FASTON"))
    operation = Task("D", "D", "RC", 3)  # no classes: its kind is its class
    assert MODEL.robot_work(screw) == 80
    assert MODEL.robot_work(mixed) == (40 + 80) / 2 + 10  # a tool change inside the wire
    assert MODEL.robot_work(unlisted) == 60 and MODEL.robot_work(operation) == 60
    assert MODEL.person_work(mixed) == (200 + 240) / 2 and MODEL.person_work(screw) == 240


def test_the_lanes_time_travel_tool_changes_and_waits_across_lanes() -> None:
    """A (robot, screwdriver, ends at the origin), P (a person's, 240 s), B (robot, the
    spring opener then the screwdriver, starts 0.3 m, 0.4 m away: 0.5 m), which must wait for P.

    A: 0 → 80 s. B: ready when P ends at 240 s; its time is the tool change before it (10 s), the
    travel 0.5 m / 0.25 m/s = 2 s, its work (40 + 80) / 2 = 60 s and the change inside it
    (10 s): 82 s, so 240 → 322 s. Robot 80 + 82 = 162 s, person 240 s, makespan 322 s.
    """
    a = Task("A", "A", "wire", 0, ("screwdriver",), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), classes=("screw",))
    p = Task("P", "P", "wire", 1, classes=("screw",))
    b = Task(
        "B",
        "B",
        "wire",
        2,
        ("spring-opener", "screwdriver"),
        (0.3, 0.4, 0.0),
        (1.0, 1.0, 0.0),
        classes=("spring", "screw"),
    )
    lanes = Lanes([a, p, b], [Precedence("P", "B", "in the way")], MODEL)
    timing = lanes.run([True, False, True])
    assert timing.start == pytest.approx((0, 0, 240)) and timing.end == pytest.approx((80, 240, 322))
    assert (timing.robot_s, timing.person_s, timing.makespan_s) == pytest.approx((162, 240, 322))
    # Without the edge the robot does not wait: B from 80 s to 162 s, the person's lane the last.
    free = Lanes([a, p, b], [], MODEL).run([True, False, True])
    assert free.end == pytest.approx((80, 240, 162)) and free.makespan_s == pytest.approx(240)


def test_a_rules_files_time_replaces_the_defaults_key_by_key() -> None:
    default = parse_rules("[time]\nperson_task_s = 240\n[time.robot_class_s]\nA = 1\nB = 2\n", "default")
    own = parse_rules("[time]\nrobot_task_s = 5\n[time.robot_class_s]\nB = 3\n", "own.toml")
    model = TimeModel.layered(default.time, own.time)
    assert (model.person_task_s, model.robot_task_s) == (240, 5)
    assert dict(model.robot_class_s) == {"A": 1, "B": 3}


def test_an_unknown_table_names_the_time_table_among_those_expected() -> None:
    with pytest.raises(
        RulesError, match=r"unknown table \[times\]; expected \[robot\], \[\[tool\]\] and \[time\]"
    ):
        parse_rules("[times]\n", "r.toml")
