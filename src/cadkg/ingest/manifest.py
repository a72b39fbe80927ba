"""The cell manifest (TOML): the cell, its input files and its static transforms.

```toml
[cell]
name = "IEMA switchgear QE01"
profile = "iema"                 # iema | elvez | elimco | vw | enki
base_iri = "https://example.org/cell/qe01/"

[[source]]
path = "ids.wri"                 # relative to this manifest
kind = "wri"                     # optional when the suffix or content tells

[[source]]
path = "scene.x3d"
frame = "cabinet"                # frame of the scene's root (scene readers only)

[derive]                         # optional: the settings of the cell's derivation
approach_distance = 0.15         # (IEMA's cabinet geometry: cadkg.usecases.iema.derive.settings)

[[frame]]
parent = "world"
child = "cabinet"
xyz = [1.2, 0.0, 0.0]            # metres
rpy = [0.0, 0.0, 1.5708]         # or quaternion = [x, y, z, w]
```
Unknown keys are errors naming the key and its line, because a misspelt key
(``kinds = ...``) would otherwise be ignored silently. The keys of ``[derive]`` are those the
derivation of the cell's profile declares (:class:`cadkg.usecase.Settings`), checked by it.
"""

from __future__ import annotations

import math
import re
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pyoxigraph as ox

from cadkg.errors import ManifestError
from cadkg.geometry.frames import Quaternion, normalize_quaternion, quaternion_from_rpy
from cadkg.registry import derive_settings, kinds, use_cases

__all__ = ["CellSpec", "FrameSpec", "Manifest", "SourceSpec", "finite", "load_manifest"]

_KEYS = {
    "": {"cell", "source", "frame", "derive", "plan"},
    "cell": {"name", "profile", "base_iri", "description"},
    "source": {"path", "kind", "description", "frame"},
    "plan": {"rules"},
    "frame": {"parent", "child", "xyz", "rpy", "quaternion"},
}
_FRAME_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_./-]*$")
_FRAME_EXPECTED = "letters, digits, _ . / - (a ROS frame id)"


@dataclass(frozen=True, slots=True)
class CellSpec:
    name: str
    profile: str
    base_iri: str
    description: str | None


@dataclass(frozen=True, slots=True)
class SourceSpec:
    """One input file: ``path`` is absolute, ``rel`` as written in the manifest."""

    path: Path
    rel: str
    kind: str | None
    line: int
    frame: str | None = None


@dataclass(frozen=True, slots=True)
class FrameSpec:
    """A static transform: ``child`` expressed in ``parent`` (metres, unit quaternion)."""

    parent: str
    child: str
    xyz: tuple[float, float, float]
    quaternion: Quaternion
    line: int


@dataclass(frozen=True, slots=True)
class Manifest:
    path: Path
    cell: CellSpec
    sources: tuple[SourceSpec, ...]
    frames: tuple[FrameSpec, ...]
    # The settings of the cell's derivation ([derive]) as its Settings.read gives them; None
    # when it declares none, or for a manifest made in code.
    derive: Any = None
    # [plan] rules: the robot's rules file for `cadkg plan` (docs/plan.md)
    plan_rules: Path | None = None


class _Locator:
    """Finds the line of a key inside ``[table]`` or the n-th ``[[table]]``: tomllib gives none."""

    def __init__(self, text: str) -> None:
        self.lines = text.splitlines()

    def line(self, table: str, index: int | None, key: str | None) -> int | None:
        """Line of ``key`` in ``[table]`` (or its ``index``-th ``[[table]]``), of a sub-table
        ``[table.key]``, or of ``table`` itself: a header or a top-level ``table = ...``."""
        current: tuple[str, ...] = ()
        count = -1
        table_line = None
        for number, raw in enumerate(self.lines, start=1):
            stripped = raw.strip()
            header = re.match(r"^\[\[?\s*([^\]]+?)\s*\]\]?", stripped)
            if header:
                current = tuple(part.strip().strip("\"'") for part in header.group(1).split("."))
                if current[0] == table:
                    if len(current) == 1:
                        count += 1
                        if index is None or count == index:
                            table_line = number
                    elif key is not None and current[1] == key and (index is None or count == index):
                        return number
                    elif key is None and table_line is None:
                        table_line = number
                continue
            assignment = re.match(r"^[\"']?([\w-]+)[\"']?\s*(=|\.)", stripped)
            if assignment is None:
                continue
            if not current and key is None and assignment.group(1) == table:
                return number
            in_table = current[:1] == (table,) and len(current) == 1 and (index is None or count == index)
            if key is not None and in_table and assignment.group(1) == key:
                return number
        return table_line


def load_manifest(path: str | Path) -> Manifest:
    """Read and check a manifest.

    Raises
    ------
    ManifestError
        On TOML syntax errors, unknown or missing keys, wrong value types, an unknown
        profile or kind, or a source file that does not exist; names file and line.
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as err:
        raise ManifestError(path, f"cannot read the manifest: {err}") from err
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        match = re.search(r"line (\d+)", str(err))
        raise ManifestError(
            path, f"TOML syntax error: {err}", line=int(match.group(1)) if match else None
        ) from None
    locate = _Locator(text)

    def fail(table: str, index: int | None, key: str | None, reason: str, **kw: Any) -> ManifestError:
        return ManifestError(path, reason, line=locate.line(table, index, key), **kw)

    for key in data:
        if key not in _KEYS[""]:
            raise ManifestError(
                path,
                f"unknown key {key!r}",
                line=locate.line(key, None, None),
                expected="cell, source, frame, derive or plan",
            )
    if not isinstance(data.get("cell"), dict):
        raise ManifestError(path, "missing [cell] table", expected="[cell] with name, profile, base_iri")
    for table, items in (("source", data.get("source", [])), ("frame", data.get("frame", []))):
        if not isinstance(items, list):
            raise fail(table, None, None, f"'{table}' must be an array of tables", expected=f"[[{table}]]")

    def check_keys(table: str, index: int | None, entry: dict[str, Any]) -> None:
        for key in entry:
            if key not in _KEYS[table]:
                raise fail(
                    table,
                    index,
                    key,
                    f"unknown key {key!r} in [{table}]",
                    expected=", ".join(sorted(_KEYS[table])),
                )

    def string(
        table: str, index: int | None, entry: dict[str, Any], key: str, required: bool = True
    ) -> str | None:
        value = entry.get(key)
        if value is None:
            if required:
                raise fail(table, index, None, f"missing key {key!r} in [{table}]")
            return None
        if not isinstance(value, str) or not value.strip():
            raise fail(table, index, key, f"{key!r} must be a non-empty string", found=value)
        return value.strip()

    cell = data["cell"]
    check_keys("cell", None, cell)
    profile = string("cell", None, cell, "profile")
    profiles = [c.name for c in use_cases()]
    if profile not in profiles:
        raise fail("cell", None, "profile", "unknown profile", found=profile, expected=" | ".join(profiles))
    base_iri = string("cell", None, cell, "base_iri")
    assert base_iri is not None and profile is not None
    if not re.match(r"^[a-z][a-z0-9+.-]*:[^\s<>\"{}|\\^`]*[/#]$", base_iri) or not _is_iri(base_iri):
        raise fail(
            "cell",
            None,
            "base_iri",
            "malformed base IRI",
            found=base_iri,
            expected="an absolute IRI ending in / or #, e.g. https://example.org/cell/qe01/",
        )
    cell_spec = CellSpec(
        name=string("cell", None, cell, "name") or "",
        profile=profile,
        base_iri=base_iri,
        description=string("cell", None, cell, "description", required=False),
    )

    known_kinds = {r.kind for r in kinds()}
    sources = []
    seen_paths: dict[Path, int] = {}
    for index, entry in enumerate(data.get("source", [])):
        check_keys("source", index, entry)
        rel = string("source", index, entry, "path")
        kind = string("source", index, entry, "kind", required=False)
        assert rel is not None
        line = locate.line("source", index, "path") or 0
        if kind is not None and kind not in known_kinds:
            raise fail(
                "source", index, "kind", "unknown kind", found=kind, expected=", ".join(sorted(known_kinds))
            )
        try:
            resolved = (path.parent / rel).resolve()
            found = resolved.is_file()
        except (OSError, ValueError):  # a name too long for the file system, a NUL byte
            found = False
        if not found:
            raise fail(
                "source",
                index,
                "path",
                "source file not found",
                found=rel,
                expected="a file path relative to the manifest",
            )
        if resolved in seen_paths:
            raise fail(
                "source",
                index,
                "path",
                f"file listed twice (first on line {seen_paths[resolved]})",
                found=rel,
            )
        seen_paths[resolved] = line
        frame_name = string("source", index, entry, "frame", required=False)
        if frame_name is not None and not _FRAME_NAME.match(frame_name):
            raise fail(
                "source", index, "frame", "malformed frame name", found=frame_name, expected=_FRAME_EXPECTED
            )
        sources.append(
            SourceSpec(path=resolved, rel=Path(rel).as_posix(), kind=kind, line=line, frame=frame_name)
        )

    frames = []
    children: dict[str, int] = {}
    for index, entry in enumerate(data.get("frame", [])):
        check_keys("frame", index, entry)
        parent = string("frame", index, entry, "parent")
        child = string("frame", index, entry, "child")
        assert parent is not None and child is not None
        line = locate.line("frame", index, "child") or 0
        for key, name in (("parent", parent), ("child", child)):
            if not _FRAME_NAME.match(name):
                raise fail(
                    "frame",
                    index,
                    key,
                    "malformed frame name",
                    found=name,
                    expected=_FRAME_EXPECTED,
                )
        if child in children:
            raise fail(
                "frame", index, "child", f"frame {child!r} already has a parent (line {children[child]})"
            )
        children[child] = line
        xyz = _vector(fail, index, entry, "xyz", 3, default=(0.0, 0.0, 0.0))
        if "rpy" in entry and "quaternion" in entry:
            raise fail("frame", index, "quaternion", "give rpy or quaternion, not both")
        if "quaternion" in entry:
            try:
                quaternion = normalize_quaternion(_vector(fail, index, entry, "quaternion", 4))
            except ValueError as err:
                raise fail(
                    "frame", index, "quaternion", str(err), expected="a unit quaternion [x, y, z, w]"
                ) from None
        else:
            roll, pitch, yaw = _vector(fail, index, entry, "rpy", 3, default=(0.0, 0.0, 0.0))
            quaternion = quaternion_from_rpy(roll, pitch, yaw)
        frames.append(FrameSpec(parent, child, (xyz[0], xyz[1], xyz[2]), quaternion, line))
    _check_tree(path, frames)
    return Manifest(
        path=path.resolve(),
        cell=cell_spec,
        sources=tuple(sources),
        frames=tuple(frames),
        derive=_derive_settings(fail, profile, data.get("derive")),
        plan_rules=_plan_rules(fail, path, data.get("plan")),
    )


def _plan_rules(fail: Any, path: Path, table: object) -> Path | None:
    if table is None:
        return None
    if not isinstance(table, dict) or set(table) - _KEYS["plan"]:
        raise fail("plan", None, None, "[plan] takes only rules", expected='[plan] rules = "robot.toml"')
    rules = table.get("rules")
    if not isinstance(rules, str) or not rules:
        raise fail("plan", None, "rules", "rules must name a file", found=rules, expected='"robot.toml"')
    resolved = (path.parent / rules).resolve()
    if not resolved.is_file():
        raise fail("plan", None, "rules", "no such rules file", found=rules)
    return resolved


def _derive_settings(fail: Any, profile: str, table: object) -> Any:
    settings = derive_settings(profile)
    if table is None:
        table = {}
    if not isinstance(table, dict):
        raise fail("derive", None, None, "'derive' must be a table", expected="[derive]")
    keys = settings.keys if settings is not None else frozenset()
    for key in table:
        if key not in keys:
            raise fail(
                "derive",
                None,
                key,
                f"unknown key {key!r} in [derive]",
                expected=", ".join(sorted(keys)) or f"no [derive] in a {profile} cell",
            )
    if settings is None:
        return None
    return settings.read(table, lambda key, reason, **kw: fail("derive", None, key, reason, **kw))


def _is_iri(text: str) -> bool:
    # The store's own parser (RFC 3987): a ']' in a path or a bad %-escape fails here, not at load.
    try:
        ox.NamedNode(text)
    except ValueError:
        return False
    return True


def finite(value: object) -> bool:
    """A TOML number a float can hold: an integer of 400 digits is refused like ``inf``."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        return False
    try:
        return math.isfinite(value)
    except OverflowError:
        return False


def _vector(
    fail: Any,
    index: int,
    entry: dict[str, Any],
    key: str,
    size: int,
    default: tuple[float, ...] | None = None,
) -> tuple[float, ...]:
    value = entry.get(key)
    if value is None and default is not None:
        return default
    if not isinstance(value, list) or len(value) != size or not all(finite(v) for v in value):
        raise fail(
            "frame",
            index,
            key,
            f"{key!r} must be {size} numbers",
            found=value,
            expected=f"[{', '.join(['0.0'] * size)}]",
        )
    return tuple(float(v) for v in value)


def _check_tree(path: Path, frames: list[FrameSpec]) -> None:
    parent_of = {f.child: f for f in frames}
    for frame in frames:
        seen = {frame.child}
        node = frame.parent
        while node in parent_of:
            if node in seen:
                raise ManifestError(
                    path,
                    f"frame {frame.child!r} is its own ancestor",
                    line=frame.line,
                    expected="a tree of frames",
                )
            seen.add(node)
            node = parent_of[node].parent
