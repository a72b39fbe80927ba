"""Every reader attacked with generated variants: each is read within the limits or refused in one
line naming the file, and its memory and CPU time per byte stay under a bound of its own.

The variants are those of :mod:`tests.security.reader_attacks`, read as a build reads them
(in the limited child, from a fresh process). The fast tier reads them at 32 KiB, the slow one
at 1 MiB. A read's CPU time is counted in reference loops (:mod:`tests.security.reference_loop`)
timed on the same CPU just before and after it, not in seconds: a process sharing its core
with others can take two to three times the CPU seconds it takes alone, and the loop beside it
takes longer alike. The bounds are about three times the worst measured on a shared 2-core
machine at either size, quiet and loaded (docs/server.md, "Bounded memory on input files"). So
a loaded machine passes and a reader that starts to build much more per byte does not; a small
allowance on top absorbs what a file of a few KiB cannot show per byte (a page more or less, a
scheduler tick).
"""

from __future__ import annotations

from pathlib import Path

import pytest

from cadkg.registry import kinds
from tests.security.reader_attacks import FAMILIES, SEEDS, Measured, attacks, measure

SMALL = 32 << 10
LARGE = 1 << 20
# A peak a few hundred KiB off and a few hundredths of a second are noise, not a reader's cost.
_SLACK_BYTES = 2 << 20
_SLACK_LOOPS = 30  # about a quarter of a second on a quiet machine

# reader kind: (peak bytes of memory a byte of file, reference loops of CPU a MiB of file),
# about three times the worst of any family at 32 KiB or 1 MiB, quiet or loaded (docs/server.md),
# and no fewer than 100 loops (under a second): a reader ten times slower still fails.
BOUNDS: dict[str, tuple[float, float]] = {
    "assignments": (140, 320),
    "bill-of-materials": (6300, 8600),
    "cable-info": (150, 100),
    "component-list": (30, 280),
    "component-model": (130, 490),
    "connection-list": (7200, 5600),
    "elimco-cable-list": (2200, 5300),
    "elvez-components": (50, 100),
    "elvez-definitions": (120, 100),
    "elvez-harnesses": (110, 100),
    "elvez-ids": (140, 830),
    "elvez-mesh": (30, 100),
    "elvez-scene": (180, 760),
    "elvez-sequence": (210, 890),
    "harness-text": (90, 340),
    "hose": (150, 750),
    "kbl": (90, 100),
    "marker-table": (930, 8900),
    "parts-management": (90, 120),
    "path-info": (140, 100),
    "pin-info": (140, 100),
    "terminal-diagram": (3100, 5200),
    "terminal-schema": (3100, 3400),
    "vec": (90, 100),
    "vrml": (260, 2000),
    "wri": (170, 520),
    "x3d": (160, 480),
}

CASES = [(kind, family) for kind in sorted(FAMILIES) for family in FAMILIES[kind]]


def _measured(directory: Path, size: int) -> dict[tuple[str, str], Measured]:
    cases = [a for kind in sorted(SEEDS) for a in attacks(kind, directory / kind, size)]
    return {(m.attack.kind, m.attack.family): m for m in measure(cases)}


@pytest.fixture(scope="module")
def small(tmp_path_factory: pytest.TempPathFactory) -> dict[tuple[str, str], Measured]:
    return _measured(tmp_path_factory.mktemp("small"), SMALL)


@pytest.fixture(scope="module")
def large(tmp_path_factory: pytest.TempPathFactory) -> dict[tuple[str, str], Measured]:
    return _measured(tmp_path_factory.mktemp("large"), LARGE)


def test_every_reader_has_seeds_families_and_a_bound() -> None:
    # A reader registered without attacks (or a bound) fails here, not silently untested.
    declared = {r.kind for r in kinds()}
    assert set(SEEDS) == declared
    assert set(BOUNDS) == declared
    assert all(len(FAMILIES[kind]) >= 5 for kind in declared)


def _check(found: Measured) -> None:
    path = str(found.attack.path)
    if found.message:
        # Refused: one line naming the file, never a traceback or a child's last words.
        assert found.message.startswith(path), found.message
        assert "\n" not in found.message and "Traceback" not in found.message, found.message
    memory, loops = BOUNDS[found.attack.kind]
    assert found.peak <= memory * found.size + _SLACK_BYTES, (found, found.bytes_per_byte)
    assert found.loops <= loops * found.size / (1 << 20) + _SLACK_LOOPS, (found, found.loops_per_mib)


@pytest.mark.parametrize(("kind", "family"), CASES)
def test_an_attack_is_read_or_refused_in_one_line_within_its_bound(
    small: dict[tuple[str, str], Measured], kind: str, family: str
) -> None:
    _check(small[(kind, family)])


@pytest.mark.slow
@pytest.mark.parametrize(("kind", "family"), CASES)
def test_a_larger_attack_is_read_or_refused_in_one_line_within_its_bound(
    large: dict[tuple[str, str], Measured], kind: str, family: str
) -> None:
    _check(large[(kind, family)])


# At 32 KiB a time that grows with the square of one element's attributes or one line's length
# is a few hundredths of a second, too little to see; at 512 KiB these readers took 5 to 13 s
# of CPU (lxml's attrib.items(), shlex; 600 to 1,500 reference loops), and take well under a
# second now. Each case reads
# through the long element or line before the outcome named (records, or the refusal's reason).
@pytest.mark.parametrize(
    ("kind", "family", "outcome"),
    [
        ("x3d", "x3d-many-attributes", "records"),
        ("elvez-scene", "x3d-many-attributes", "records"),
        ("pin-info", "xml-many-attributes", "unknown attribute 'a0' of <pin>"),
        ("path-info", "xml-many-attributes", "unknown attribute 'a0' of <path>"),
        ("cable-info", "xml-many-attributes", "unknown attribute 'a0' of <cable>"),
        # The seed's own statements follow the long line, so the second protection P2 is refused.
        ("harness-text", "harness-long-row", "protection declared twice"),
        ("harness-text", "harness-many-columns", "protection declared twice"),
    ],
)
def test_one_long_element_or_line_is_read_in_time_linear_in_it(
    tmp_path: Path, kind: str, family: str, outcome: str
) -> None:
    import time

    from cadkg.errors import IngestError
    from cadkg.registry import reader_for
    from tests.security.reference_loop import reference_seconds

    cases = {a.family: a.path for a in attacks(kind, tmp_path, 512 << 10)}
    read = reader_for(kind).read
    list(read(cases[family.split("-", 1)[0] + "-seed"]))  # the reader's modules imported first
    ahead = reference_seconds()
    started = time.process_time()
    try:
        found = "records" if list(read(cases[family])) else "no records"
    except IngestError as err:
        found = str(err)
    loops = (time.process_time() - started) / ((ahead + reference_seconds()) / 2)
    assert outcome in found
    assert loops < 150, loops  # about 1.3 s on a quiet machine; linear reads take 20 or fewer


# What the attacks found: int() and float() raised where the input was not what they take.
_HUGE = "9" * 5000


def _refused(kind: str, path: Path) -> str:
    from cadkg.errors import IngestError
    from cadkg.registry import reader_for

    with pytest.raises(IngestError) as info:
        list(reader_for(kind).read(path))
    message = str(info.value)
    assert message.startswith(str(path)) and "\n" not in message, message
    return message


@pytest.mark.parametrize("order", [_HUGE, "²"])
def test_an_assembly_order_int_refuses_is_a_located_error(tmp_path: Path, order: str) -> None:
    path = tmp_path / "Assembly_sequence.csv"
    path.write_text(f"Order;Type of operation;Label;Spot\n1;EC;WH1;C1.1.L\n{order};EC;WH2;C1.2.L\n")
    assert _refused("elvez-sequence", path).startswith(f"{path}:3: Order is not a whole number from 1")


def test_a_shared_string_index_of_thousands_of_digits_is_no_internal_error(tmp_path: Path) -> None:
    from tests.security.reader_attacks import _write_xlsx

    rows: list[list[object]] = [["Terminal block", "Position", "Terminal", "Cad ID", "Commercial", "Levels"]]
    path = _write_xlsx(
        tmp_path / "t.xlsx", "S", [*rows, ["X1", 1, "1", "ID000001", "T", "a"]], False, True, True
    )
    assert "ValueError" not in _refused("terminal-diagram", path)


@pytest.mark.parametrize(
    ("old", "new"),
    [("<Knots>1</Knots>", "<Knots>one</Knots>"), ("<Degree>1</Degree>", f"<Degree>{_HUGE}</Degree>")],
    ids=["knot not a number", "degree of 5000 digits"],
)
def test_a_vec_curve_of_numbers_python_refuses_is_a_located_error(tmp_path: Path, old: str, new: str) -> None:
    from tests.security.reader_attacks import DATA

    text = (DATA / "vec" / "modules-2.0.vec").read_text(encoding="utf-8")
    assert old in text
    path = tmp_path / "curve.vec"
    path.write_text(text.replace(old, new), encoding="utf-8")
    assert "is not a B-spline" in _refused("vec", path)


def test_a_kbl_curve_degree_of_thousands_of_digits_is_a_located_error(tmp_path: Path) -> None:
    from tests.security.reader_attacks import DATA

    text = (DATA / "kbl" / "kblxml_2.3sr-1_000971228_ltgs_batterie_plus_170718.kbl").read_text(
        encoding="utf-8"
    )
    path = tmp_path / "curve.kbl"
    path.write_text(text.replace("<Degree>6</Degree>", f"<Degree>{_HUGE}</Degree>", 1), encoding="utf-8")
    from cadkg.registry import reader_for

    try:
        list(reader_for("kbl").read(path))
    except Exception as err:  # a located refusal is fine; Python's own ValueError is not
        from cadkg.errors import IngestError

        assert isinstance(err, IngestError) and str(err).startswith(str(path)), err
