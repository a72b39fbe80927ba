"""Every ELVEZ file is recognised from its content: the ELVEZ kinds share .xml and .csv with other
use cases (each file is claimed by exactly one sniffer), and .x3d and .wri with the core readers
(the cell's profile picks the reader no content tells apart)."""

from __future__ import annotations

from pathlib import Path

import pytest

from cadkg.errors import IngestError
from cadkg.registry import kinds, sniff_kind
from cadkg.usecases.elvez.files.xml_fields import element_names
from tests.conftest import ROOT

EXAMPLES = ROOT / "examples"
ELVEZ = EXAMPLES / "elvez-cell"
IEMA = EXAMPLES / "iema-switchgear"
ELVEZ_KINDS = {r.kind for r in kinds() if r.kind.startswith("elvez-")}

ELVEZ_FILES = {
    "Jigs_definition_v2.xml": "elvez-definitions",
    "WH_configuration.xml": "elvez-harnesses",
    "Components_definition.csv": "elvez-components",
    "Assembly_sequence.csv": "elvez-sequence",
    "platform_cad.x3d": "elvez-scene",
    "combs_ids.wri": "elvez-ids",
    "stl/platform/0011.STL": "elvez-mesh",
    "stl/combs/ID0002.STL": "elvez-mesh",
}
IEMA_FILES = {
    "components.xml": "component-model",
    "component-list.csv": "component-list",
    "terminals.csv": "terminal-schema",
    "lista-cablaggio.csv": "connection-list",
    "komax-export.csv": "connection-list",
    "connections-fig3.tsv": "connection-list",
    "assignments.csv": "assignments",
    "scene.x3d": "x3d",
    "ids.wri": "wri",
}


@pytest.mark.parametrize(("name", "kind"), sorted(ELVEZ_FILES.items()))
def test_elvez_example_files(name: str, kind: str) -> None:
    assert sniff_kind(ELVEZ / name, profile="elvez") == kind


@pytest.mark.parametrize(("name", "kind"), sorted(IEMA_FILES.items()))
def test_iema_example_files_keep_their_kinds(name: str, kind: str) -> None:
    for profile in ("", "iema", "vw"):
        assert sniff_kind(IEMA / name, profile=profile) == kind
    head = (IEMA / name).read_bytes()[:16384]
    assert [r.kind for r in kinds() if r.kind in ELVEZ_KINDS and r.sniff is not None and r.sniff(head)] == []


def test_scenes_and_id_tables_are_the_cells_use_case_s() -> None:
    # The same files in a cell of another profile are read by the core readers.
    assert sniff_kind(ELVEZ / "platform_cad.x3d", profile="iema") == "x3d"
    assert sniff_kind(ELVEZ / "platform_ids.wri") == "wri"
    assert sniff_kind(IEMA / "scene.x3d", profile="elvez") == "elvez-scene"


@pytest.mark.parametrize("name", sorted(n for n in ELVEZ_FILES if n.endswith((".xml", ".csv"))))
def test_only_one_sniffer_claims_each_elvez_file(name: str) -> None:
    head = (ELVEZ / name).read_bytes()[:16384]
    assert [r.kind for r in kinds() if r.sniff is not None and r.sniff(head)] == [ELVEZ_FILES[name]]


def test_element_names_skip_declaration_and_comments() -> None:
    head = (
        b'\xef\xbb\xbf<?xml version="1.0"?>\n<!-- <jig> in a comment -->\n<?pi x?>\n<data>\n<!--x-->\n<box>'
    )
    assert element_names(head) == ["data", "box"]
    assert element_names(b"<!-- never closed <jig>") == []
    assert element_names(b"plain text") == []


def test_an_xml_no_reader_knows(tmp_path: Path) -> None:
    path = tmp_path / "other.xml"
    path.write_text("<robots><robot/></robots>")
    with pytest.raises(IngestError, match=r"other\.xml: cannot tell the kind of this file"):
        sniff_kind(path, profile="elvez")
