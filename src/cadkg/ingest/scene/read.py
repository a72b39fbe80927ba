"""The scene readers: X3D and VRML97 files, with the Inline files they name, as items."""

from __future__ import annotations

from pathlib import Path

from cadkg.ingest.scene.nodes import Parser
from cadkg.ingest.scene.records import SceneItem
from cadkg.ingest.scene.vrml import parse_vrml
from cadkg.ingest.scene.walk import STRICT, WalkOptions, read_scene
from cadkg.ingest.scene.x3d import parse_x3d, x3d_parser

__all__ = ["PARSERS", "WalkOptions", "read_vrml", "read_x3d"]

# An Inline file is parsed by its suffix, whichever encoding names it.
PARSERS: dict[str, Parser] = {".x3d": parse_x3d, ".wrl": parse_vrml}


def read_x3d(path: str | Path, options: WalkOptions = STRICT) -> list[SceneItem]:
    """Read an X3D scene (and its Inline files) as items with frames, boxes and meshes.

    ``options`` make the read forgiving of broken shapes (see :class:`WalkOptions`); by default
    every problem below is an error.

    Raises
    ------
    IngestError
        On unreadable, empty or binary files, malformed XML, entity declarations, a missing
        ``<Scene>``, bad numbers, duplicate DEF names, a USE of an item, and Inline urls that
        are remote, absolute, outside the scene's directory, missing or cyclic.
    """
    if not options.skip_broken_shapes:
        return read_scene(path, parse_x3d, PARSERS)
    tolerant = x3d_parser(tolerate_geometry_defs=True)
    return read_scene(path, tolerant, {**PARSERS, ".x3d": tolerant}, options)


def read_vrml(path: str | Path) -> list[SceneItem]:
    """Read a VRML97 scene (and its Inline files) as items with frames, boxes and meshes.

    Raises
    ------
    IngestError
        On unreadable, empty or binary files, a header other than ``#VRML V2.0 utf8``, syntax
        errors (unexpected token, unterminated string, bracket or brace), bad numbers,
        duplicate DEF names, a USE of an item, and Inline urls that are remote, absolute,
        outside the scene's directory, missing or cyclic.
    """
    return read_scene(path, parse_vrml, PARSERS)
