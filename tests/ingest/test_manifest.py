"""The cell manifest: the example loads; every mistake is a ManifestError at the exact line."""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import pytest

import cadkg.registry as registry
from cadkg.errors import IngestError, ManifestError
from cadkg.ingest.manifest import CellSpec, load_manifest
from cadkg.usecase import Settings, UseCase
from tests.toys import toy_derivation

REPO = Path(__file__).resolve().parents[2]
EXAMPLE = REPO / "examples" / "iema-switchgear"

CELL = """\
[cell]
name = "Test cell"
profile = "iema"
base_iri = "https://example.org/cell/t/"
"""  # lines 1-4

SOURCES = """\

[[source]]
path = "ids.wri"
kind = "wri"

[[source]]
path = "conn.tsv"
"""  # lines 5-11: first path on 7, second [[source]] on 10, its path on 11


@pytest.fixture
def cell_dir(tmp_path: Path) -> Path:
    (tmp_path / "ids.wri").write_bytes(b"ID000041\tX00005.2\t6013277\r\n")
    (tmp_path / "conn.tsv").write_bytes((EXAMPLE / "connections-fig3.tsv").read_bytes())
    return tmp_path


def manifest(cell_dir: Path, text: str) -> Path:
    path = cell_dir / "manifest.toml"
    path.write_text(text, encoding="utf-8")
    return path


def error_of(path: Path) -> ManifestError:
    with pytest.raises(ManifestError) as info:
        load_manifest(path)
    err = info.value
    assert isinstance(err, IngestError)
    assert err.path == str(path)
    return err


# --- the examples ------------------------------------------------------------------------------------


def test_example_manifest_loads() -> None:
    m = load_manifest(EXAMPLE / "manifest.toml")
    assert m.path == (EXAMPLE / "manifest.toml").resolve()
    assert m.cell == CellSpec(
        name="IEMA switchgear QE01",
        profile="iema",
        base_iri="https://example.org/cell/iema-qe01/",
        description=None,
    )
    # No kinds: each file's is told by its content.
    names = [
        "ids.wri",
        "components.xml",
        "pins.xml",
        "component-list.csv",
        "schema-morsetti.ods",
        "scene.x3d",
        "lista-cablaggio.csv",
        "distinta-componenti.xlsx",
        "qr-markers.ods",
        "assignments.csv",
    ]
    lines = [8, 11, 14, 17, 20, 23, 27, 30, 33, 36]
    assert [(s.path, s.rel, s.kind, s.line) for s in m.sources] == [
        ((EXAMPLE / name).resolve(), name, None, line) for name, line in zip(names, lines, strict=True)
    ]
    assert all(s.path.is_absolute() and s.path.is_file() for s in m.sources)
    (frame,) = m.frames
    assert (frame.parent, frame.child, frame.xyz, frame.line) == ("world", "cabinet", (1.2, 0.0, 0.0), 45)
    assert frame.quaternion == pytest.approx((0.0, 0.0, 0.7071068, 0.7071068), abs=1e-7)


def test_fig3_manifest_leaves_the_wri_kind_to_the_registry() -> None:
    m = load_manifest(EXAMPLE / "manifest-fig3.toml")
    assert m.cell.name == "IEMA switchgear QE01 (Figure 3 excerpt)"
    assert [(s.rel, s.kind, s.line) for s in m.sources] == [
        ("ids.wri", None, 9),
        ("connections-fig3.tsv", "connection-list", 12),
    ]


def test_inline_manifest_loads(cell_dir: Path) -> None:
    m = load_manifest(manifest(cell_dir, CELL + SOURCES))
    assert [(s.path, s.rel, s.kind, s.line) for s in m.sources] == [
        (cell_dir / "ids.wri", "ids.wri", "wri", 7),
        (cell_dir / "conn.tsv", "conn.tsv", None, 11),
    ]
    assert m.frames == ()


def test_kind_omitted_for_wri_is_none(cell_dir: Path) -> None:
    m = load_manifest(manifest(cell_dir, CELL + '\n[[source]]\npath = "ids.wri"\n'))
    assert [(s.rel, s.kind) for s in m.sources] == [("ids.wri", None)]


def test_frames_with_quaternion_and_defaults(cell_dir: Path) -> None:
    text = (
        CELL + "\n[[frame]]\nparent = 'world'\nchild = 'cabinet'\nquaternion = [0, 0, 0, 1.0004]\n"
        "\n[[frame]]\nparent = 'cabinet'\nchild = 'rail_1'\n"
    )
    m = load_manifest(manifest(cell_dir, text))
    first, second = m.frames
    assert first.quaternion == pytest.approx((0.0, 0.0, 0.0, 1.0))
    assert math.isclose(sum(v * v for v in first.quaternion), 1.0)
    assert (first.xyz, first.line) == ((0.0, 0.0, 0.0), 8)
    assert (second.parent, second.child, second.quaternion, second.line) == (
        "cabinet",
        "rail_1",
        (0.0, 0.0, 0.0, 1.0),
        13,
    )


# --- errors at the exact line ------------------------------------------------------------------------

FRAME = """\

[[frame]]
parent = "world"
child = "cabinet"
"""  # lines 12-15 after CELL + SOURCES: [[frame]] on 13, parent 14, child 15


@pytest.mark.parametrize(
    ("text", "line", "reason"),
    [
        ('[cells]\nname = "x"\n\n' + CELL, 1, "unknown key 'cells'"),
        (CELL + 'colour = "blue"\n' + SOURCES, 5, "unknown key 'colour' in [cell]"),
        (CELL + SOURCES + 'kinds = "connection-list"\n', 12, "unknown key 'kinds' in [source]"),
        (CELL + SOURCES + FRAME + "xzy = [1, 2, 3]\n", 16, "unknown key 'xzy' in [frame]"),
        (CELL.replace('"iema"', '"IEMA"') + SOURCES, 3, "unknown profile"),
        (CELL.replace('"iema"', '"ros"') + SOURCES, 3, "unknown profile"),
        (
            CELL.replace("https://example.org/cell/t/", "https://example.org/cell/t") + SOURCES,
            4,
            "malformed base IRI",
        ),
        (CELL.replace("https://example.org/cell/t/", "example.org/cell/") + SOURCES, 4, "malformed base IRI"),
        (
            CELL.replace("https://example.org/cell/t/", "https://example.org/a b/") + SOURCES,
            4,
            "malformed base IRI",
        ),
        (
            CELL.replace("https://example.org/cell/t/", "https://example.org/]cell/") + SOURCES,
            4,
            "malformed base IRI",
        ),
        (
            CELL.replace("https://example.org/cell/t/", "https://example.org/%zz/") + SOURCES,
            4,
            "malformed base IRI",
        ),
        (CELL + SOURCES.replace("conn.tsv", "missing.tsv"), 11, "source file not found"),
        (CELL + SOURCES.replace("conn.tsv", "x" * 300 + ".tsv"), 11, "source file not found"),
        (CELL + SOURCES.replace("conn.tsv", "conn\\u0000.tsv"), 11, "source file not found"),
        (CELL + SOURCES.replace("conn.tsv", "./sub/../ids.wri"), 11, "file listed twice (first on line 7)"),
        (CELL + SOURCES + 'kind = "wrl"\n', 12, "unknown kind"),
        (
            CELL + SOURCES + FRAME + "rpy = [0, 0, 0]\nquaternion = [0, 0, 0, 1]\n",
            17,
            "give rpy or quaternion",
        ),
        (CELL + SOURCES + FRAME + "quaternion = [0, 0, 0, 2]\n", 16, "quaternion length 2 is not 1"),
        (CELL + SOURCES + FRAME + "quaternion = [0, 0, 0]\n", 16, "'quaternion' must be 4 numbers"),
        (CELL + SOURCES + FRAME + "xyz = [1.0, 2.0]\n", 16, "'xyz' must be 3 numbers"),
        (CELL + SOURCES + FRAME + 'xyz = [1.0, 2.0, "3"]\n', 16, "'xyz' must be 3 numbers"),
        (CELL + SOURCES + FRAME + "rpy = [0, nan, 0]\n", 16, "'rpy' must be 3 numbers"),
        (CELL + SOURCES + FRAME + f"xyz = [1, 2, {'9' * 400}]\n", 16, "'xyz' must be 3 numbers"),
        (CELL + SOURCES + FRAME.replace('"cabinet"', '"my cabinet"'), 15, "malformed frame name"),
        (CELL + SOURCES + FRAME + FRAME.replace("world", "room"), 19, "frame 'cabinet' already has a parent"),
        (CELL + SOURCES + FRAME + 'parent = "x"\n', 16, "TOML syntax error"),
        (CELL + "name = \n", 5, "TOML syntax error"),
        (CELL.replace('name = "Test cell"', 'name = ""') + SOURCES, 2, "'name' must be a non-empty string"),
        (CELL.replace('profile = "iema"\n', "") + SOURCES, 1, "missing key 'profile' in [cell]"),
    ],
    ids=[
        "unknown-top-level-table",
        "unknown-key-in-cell",
        "unknown-key-in-second-source",
        "unknown-key-in-frame",
        "profile-case",
        "profile-unknown",
        "base-iri-no-slash",
        "base-iri-no-scheme",
        "base-iri-space",
        "base-iri-bracket",
        "base-iri-bad-escape",
        "missing-source-file",
        "source-name-too-long",
        "source-name-with-nul",
        "file-listed-twice",
        "unknown-kind",
        "rpy-and-quaternion",
        "non-unit-quaternion",
        "quaternion-3-numbers",
        "xyz-2-numbers",
        "xyz-string",
        "rpy-nan",
        "xyz-400-digits",
        "frame-name-space",
        "two-parents",
        "duplicate-key",
        "syntax-error",
        "empty-name",
        "missing-profile",
    ],
)
def test_error_at_exact_line(cell_dir: Path, text: str, line: int, reason: str) -> None:
    err = error_of(manifest(cell_dir, text))
    assert err.line == line, str(err)
    assert err.reason.startswith(reason), err.reason
    assert f"manifest.toml:{line}: {reason}" in str(err)


@pytest.mark.parametrize(("key", "text"), [("xzy", "xzy = [1, 2, 3]\n"), ("kind", 'kind = "wri"\n')])
def test_unknown_key_message_names_the_key_and_the_known_ones(cell_dir: Path, key: str, text: str) -> None:
    err = error_of(manifest(cell_dir, CELL + SOURCES + FRAME + text))
    assert err.line == 16
    assert err.reason == f"unknown key {key!r} in [frame]"
    assert err.expected == "child, parent, quaternion, rpy, xyz"


def test_bad_profile_lists_the_profiles(cell_dir: Path) -> None:
    err = error_of(manifest(cell_dir, CELL.replace('"iema"', '"xyz"')))
    # The use cases in the order of their sections of D3.1.
    assert (err.found, err.expected) == ("xyz", "iema | elimco | elvez | vw | enki")


def test_missing_source_names_the_file(cell_dir: Path) -> None:
    err = error_of(manifest(cell_dir, CELL + SOURCES.replace("conn.tsv", "missing.tsv")))
    assert err.found == "missing.tsv"


def test_frame_cycle(cell_dir: Path) -> None:
    text = (
        CELL + "\n[[frame]]\nparent = 'b'\nchild = 'a'\n"  # child on line 8
        "\n[[frame]]\nparent = 'a'\nchild = 'b'\n"  # child on line 12
    )
    err = error_of(manifest(cell_dir, text))
    assert err.line == 8
    assert err.reason == "frame 'a' is its own ancestor"


def test_frame_that_is_its_own_parent(cell_dir: Path) -> None:
    err = error_of(manifest(cell_dir, CELL + "\n[[frame]]\nparent = 'a'\nchild = 'a'\n"))
    assert (err.line, err.reason) == (8, "frame 'a' is its own ancestor")


def test_missing_cell_table(cell_dir: Path) -> None:
    err = error_of(manifest(cell_dir, SOURCES))
    assert err.reason == "missing [cell] table"


def test_manifest_not_utf8(cell_dir: Path) -> None:
    path = cell_dir / "manifest.toml"
    path.write_bytes(CELL.replace("Test cell", "Zelle f\xfcr L\xfcfter").encode("latin-1"))
    err = error_of(path)
    assert err.reason.startswith("cannot read the manifest")


def test_unknown_top_level_key_value_has_its_line(cell_dir: Path) -> None:
    err = error_of(manifest(cell_dir, "version = 2\n" + CELL))
    assert err.reason == "unknown key 'version'"
    assert "version" in str(err)


def test_unknown_top_level_key_value_line(cell_dir: Path) -> None:
    err = error_of(manifest(cell_dir, "version = 2\n" + CELL))
    assert err.line == 1


@pytest.mark.parametrize(
    ("extra", "line"), [("extra.z = 1\n", 5), ("\n[cell.extra]\nz = 1\n", 6)], ids=["dotted-key", "sub-table"]
)
def test_unknown_dotted_key_in_cell_has_its_line(cell_dir: Path, extra: str, line: int) -> None:
    err = error_of(manifest(cell_dir, CELL + extra))
    assert err.reason == "unknown key 'extra' in [cell]"
    assert err.line == line


@pytest.mark.parametrize(
    ("body", "line", "reason"),
    [
        ("approach_distance = -0.1\n", 14, "'approach_distance' must be a non-negative number of metres"),
        ('approach_distance = "0.1"\n', 14, "'approach_distance' must be a non-negative number of metres"),
        (f"cluster_tolerance = {'9' * 400}\n", 14, "'cluster_tolerance' must be a non-negative number"),
        ("cluster_tolerance = nan\n", 14, "'cluster_tolerance' must be a non-negative number of metres"),
        ("cluster_tolerance = true\n", 14, "'cluster_tolerance' must be a non-negative number of metres"),
        ('rail_pattern = "(RAIL"\n', 14, "not a regular expression"),
        ("approach = 0.1\n", 14, "unknown key 'approach' in [derive]"),
        ('robot_zones = "Q"\n', 14, "not a list of zone names"),
        ('robot_zones = ["Q", ""]\n', 14, "not a list of zone names"),
    ],
    ids=[
        "negative",
        "text",
        "400-digits",
        "nan",
        "boolean",
        "bad-pattern",
        "unknown-key",
        "zones-text",
        "zone-empty",
    ],
)
def test_derive_settings_errors(cell_dir: Path, body: str, line: int, reason: str) -> None:
    err = error_of(manifest(cell_dir, CELL + SOURCES + "\n[derive]\n" + body))
    assert err.line == line, str(err)
    assert err.reason.startswith(reason), err.reason


def test_derive_settings_are_read(cell_dir: Path) -> None:
    settings = 'approach_distance = 0\ncluster_tolerance = 0.004\nrail_pattern = "^R"\n'
    text = CELL + SOURCES + "\n[derive]\n" + settings
    spec = load_manifest(manifest(cell_dir, text)).derive
    assert (spec.approach_distance, spec.cluster_tolerance, spec.rail_pattern) == (0.0, 0.004, "^R")
    assert spec.robot_zones == ("Q", "QE")  # the IEMA default
    zones = load_manifest(manifest(cell_dir, text + 'robot_zones = ["Q", "P"]\n')).derive.robot_zones
    assert zones == ("Q", "P")


def _toy_case(name: str, settings: Settings | None) -> UseCase:
    title = "a cell whose derivation has settings of its own"
    return UseCase(name=name, title=title, derivation=toy_derivation(settings=settings))


def _read_speed(table: Mapping[str, Any], fail: Callable[..., Exception]) -> float:
    speed = table.get("speed", 1.0)
    if not isinstance(speed, float):
        raise fail("speed", "'speed' must be a number", found=speed)
    return speed


def test_the_derive_settings_are_those_the_derivation_of_the_profile_declares(
    cell_dir: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(registry, "_TABLE", None)
    registry.add_use_case(_toy_case("toy-speed", Settings(frozenset({"speed"}), _read_speed)))
    registry.add_use_case(_toy_case("toy-none", None))
    toy = CELL.replace('"iema"', '"toy-speed"') + SOURCES
    assert load_manifest(manifest(cell_dir, toy)).derive == 1.0
    assert load_manifest(manifest(cell_dir, toy + "\n[derive]\nspeed = 2.5\n")).derive == 2.5
    err = error_of(manifest(cell_dir, toy + "\n[derive]\nspeed = true\n"))
    assert (err.line, err.reason) == (14, "'speed' must be a number")
    # The cabinet's settings are IEMA's derivation's, not every cell's.
    err = error_of(manifest(cell_dir, toy + "\n[derive]\napproach_distance = 0.1\n"))
    assert (err.line, err.reason, err.expected) == (
        14,
        "unknown key 'approach_distance' in [derive]",
        "speed",
    )
    bare = CELL.replace('"iema"', '"toy-none"') + SOURCES
    assert load_manifest(manifest(cell_dir, bare)).derive is None
    err = error_of(manifest(cell_dir, bare + "\n[derive]\nspeed = 2.5\n"))
    assert (
        err.reason == "unknown key 'speed' in [derive]" and err.expected == "no [derive] in a toy-none cell"
    )


def test_plan_rules_are_a_file_beside_the_manifest(cell_dir: Path) -> None:
    (cell_dir / "robot.toml").write_text("[robot]\n", encoding="utf-8")
    m = load_manifest(manifest(cell_dir, CELL + SOURCES + '\n[plan]\nrules = "robot.toml"\n'))
    assert m.plan_rules == (cell_dir / "robot.toml").resolve()
    assert load_manifest(manifest(cell_dir, CELL + SOURCES)).plan_rules is None


@pytest.mark.parametrize(
    ("text", "reason"),
    [
        ('\n[plan]\nrules = "none.toml"\n', "no such rules file"),
        ("\n[plan]\nrules = 3\n", "rules must name a file"),
        ('\n[plan]\nrulez = "robot.toml"\n', "[plan] takes only rules"),
    ],
)
def test_bad_plan_rules_are_errors_at_their_line(cell_dir: Path, text: str, reason: str) -> None:
    err = error_of(manifest(cell_dir, CELL + SOURCES + text))
    assert reason in str(err) and err.line is not None and err.line >= 12
