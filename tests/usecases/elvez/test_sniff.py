"""The ELVEZ kinds share .xml and .csv with others: each file is claimed by exactly one sniffer."""

from __future__ import annotations

from pathlib import Path

import pytest

from cadkg.errors import IngestError
from cadkg.registry import kinds, sniff_kind
from cadkg.usecases.elvez.xml_fields import first_element_name
from tests.conftest import ROOT

EXAMPLES = ROOT / "examples"
ELVEZ = EXAMPLES / "elvez-cell"
IEMA = EXAMPLES / "iema-switchgear"
ELVEZ_KINDS = ("element-models", "tools", "harness-structure", "harness-components", "action-plan")

ELVEZ_FILES = {
    "assembly/assembly-models.xml": "element-models",
    "holder/holder-models.xml": "element-models",
    "atc/atc-models.xml": "element-models",
    "tools.xml": "tools",
    "harness-structure.xml": "harness-structure",
    "harness-components.csv": "harness-components",
    "action-plan.csv": "action-plan",
    "assembly/assembly.x3d": "x3d",
    "assembly/assembly.wri": "wri",
}
IEMA_FILES = {
    "components.xml": "component-model",
    "component-list.csv": "component-list",
    "terminals.csv": "terminal-schema",
    "lista-cablaggio.csv": "connection-list",
    "komax-export.csv": "connection-list",
    "connections-fig3.tsv": "connection-list",
    "assignments.csv": "assignments",
}


@pytest.mark.parametrize(("name", "kind"), sorted(ELVEZ_FILES.items()))
def test_elvez_example_files(name: str, kind: str) -> None:
    assert sniff_kind(ELVEZ / name) == kind


@pytest.mark.parametrize(("name", "kind"), sorted(IEMA_FILES.items()))
def test_iema_example_files_keep_their_kinds(name: str, kind: str) -> None:
    assert sniff_kind(IEMA / name) == kind
    head = (IEMA / name).read_bytes()[:16384]
    elvez = [r.kind for r in kinds() if r.kind in ELVEZ_KINDS and r.sniff is not None and r.sniff(head)]
    assert elvez == []


@pytest.mark.parametrize("name", sorted(n for n in ELVEZ_FILES if not n.endswith((".x3d", ".wri"))))
def test_only_one_sniffer_claims_each_elvez_file(name: str) -> None:
    head = (ELVEZ / name).read_bytes()[:16384]
    assert [r.kind for r in kinds() if r.sniff is not None and r.sniff(head)] == [ELVEZ_FILES[name]]


def test_first_element_skips_declaration_and_comments() -> None:
    head = b'\xef\xbb\xbf<?xml version="1.0"?>\n<!-- <tools> in a comment -->\n<?pi x?>\n<harness_structure>'
    assert first_element_name(head) == "harness_structure"
    assert first_element_name(b"<!-- never closed <tools>") is None
    assert first_element_name(b"plain text") is None


def test_an_xml_no_reader_knows(tmp_path: Path) -> None:
    path = tmp_path / "other.xml"
    path.write_text("<robots><robot/></robots>")
    with pytest.raises(IngestError, match=r"other\.xml: cannot tell the kind of this file"):
        sniff_kind(path)
