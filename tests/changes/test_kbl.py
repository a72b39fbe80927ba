"""A KBL harness against a copy exported again: XML ids renumbered, one wire changed."""

from __future__ import annotations

import re
from pathlib import Path

import cadkg
from cadkg.changes import diff_graphs
from tests.conftest import ROOT

KBL = ROOT / "tests" / "data" / "kbl" / "kblxml_2.3sr-1_000971619_ltgs_movo_170718.kbl"
MANIFEST = """[cell]
name = "harness"
profile = "vw"
base_iri = "https://example.org/cell/harness/"

[[source]]
path = "harness.kbl"
"""


def _cell(folder: Path, text: str) -> cadkg.KnowledgeGraph:
    folder.mkdir()
    (folder / "harness.kbl").write_text(text, encoding="utf-8")
    (folder / "manifest.toml").write_text(MANIFEST, encoding="utf-8")
    return cadkg.build(folder / "manifest.toml")


def renumbered(text: str) -> str:
    """``text`` with every XML id and every reference to it renamed, as another export numbers them."""
    ids = sorted(set(re.findall(r'\bid="([^"]+)"', text)), key=len, reverse=True)
    names = {old: f"x{n:04d}" for n, old in enumerate(reversed(ids))}
    token = re.compile(r'(?<=[>"\s])(' + "|".join(map(re.escape, ids)) + r')(?=[<"\s])')
    return token.sub(lambda m: names[m.group(1)], text)


def _wire_length(text: str, number: str, length: str) -> str:
    """``text`` with the DMU length of wire ``number`` set to ``length`` (mm)."""
    wire = re.compile(
        r"(<General_wire_occurrence[^>]*>(?:(?!</General_wire_occurrence>).)*?<Value_component>)([^<]+)"
        r"(</Value_component>(?:(?!</General_wire_occurrence>).)*?<Wire_number>"
        + re.escape(number)
        + "</Wire_number>)",
        re.DOTALL,
    )
    changed, count = wire.subn(lambda m: m.group(1) + length + m.group(3), text)
    assert count == 1
    return changed


def test_renumbered_ids_are_no_change(tmp_path: Path) -> None:
    text = KBL.read_text(encoding="utf-8")
    again = renumbered(text)
    assert again != text and "id_350_0" in text and "id_350_0" not in again
    old, new = _cell(tmp_path / "old", text), _cell(tmp_path / "new", again)
    assert (
        old.query("SELECT ?w WHERE { ?w a ck:Wire }").rows
        != new.query("SELECT ?w WHERE { ?w a ck:Wire }").rows
    )
    changes = diff_graphs(old, new)
    assert [(c.change, c.kind) for c in changes] == [("changed", "file")]


def test_one_wire_changed_is_one_change(tmp_path: Path) -> None:
    text = KBL.read_text(encoding="utf-8")
    old = _cell(tmp_path / "old", text)
    new = _cell(tmp_path / "new", _wire_length(renumbered(text), "7", "999.5"))
    changes = [c for c in diff_graphs(old, new) if c.kind != "file"]
    assert [(c.change, c.kind, c.id) for c in changes] == [("changed", "wire", "7")]
    (wire,) = changes
    assert wire.attributes["length"][1] == "0.9995"
    assert wire.old_iri != wire.new_iri  # matched by number and ends, not by IRI
