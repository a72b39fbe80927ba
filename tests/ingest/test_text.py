"""Decoding of text exports: UTF-16 with and without its BOM, and BOMs inside a file."""

from __future__ import annotations

import shutil
import warnings
from pathlib import Path

import pytest

from cadkg.errors import IngestError, IngestWarning
from cadkg.ingest.eplan.connection_list import read_connection_list
from cadkg.ingest.harness.kbl import read_kbl
from cadkg.ingest.scene.read import read_x3d
from cadkg.ingest.scene.records import SceneItem
from cadkg.ingest.text import decode_text, sniffable_head
from cadkg.ingest.wri import read_wri
from cadkg.registry import sniff_kind
from cadkg.usecases.iema.component_model import read_component_models
from tests.conftest import ROOT

IEMA = ROOT / "examples" / "iema-switchgear"
KBL_SAMPLE = ROOT / "tests" / "data" / "kbl" / "two-core-fixing-tape.kbl"
TEXT = "Cad ID\tLabel\tCommercial\r\nID000041\t=-X00005.2\t6013277\r\nID000045\tF1500.1\t\r\n"


def _quiet(read, *args, **kwargs):  # type: ignore[no-untyped-def]
    with warnings.catch_warnings():
        warnings.simplefilter("error", IngestWarning)  # a clean read warns about nothing
        return read(*args, **kwargs)


@pytest.mark.parametrize("encoding", ["utf-16", "utf-16-be"])
def test_utf16_with_its_bom_decodes_without_a_warning(encoding: str) -> None:
    data = TEXT.encode(encoding)
    if encoding == "utf-16-be":
        data = b"\xfe\xff" + data
    assert data[:2] in (b"\xff\xfe", b"\xfe\xff")
    assert _quiet(decode_text, "t.wri", data, expected="x") == TEXT  # the BOM is gone too


@pytest.mark.parametrize(("encoding", "named"), [("utf-16-le", "UTF-16-LE"), ("utf-16-be", "UTF-16-BE")])
def test_utf16_without_a_bom_is_read_with_a_warning(encoding: str, named: str) -> None:
    with pytest.warns(IngestWarning, match=f"UTF-16 without a byte-order mark; read as {named}") as caught:
        text = decode_text("t.wri", TEXT.encode(encoding), expected="x")
    assert text == TEXT
    warning = next(w.message for w in caught if isinstance(w.message, IngestWarning))
    assert (warning.path, warning.line) == ("t.wri", 1)


def test_broken_utf16_names_the_line() -> None:
    data = "a\nb\n".encode("utf-16") + b"\x00\xd8" + "c\n".encode("utf-16-le")  # a lone high surrogate
    with pytest.raises(IngestError, match=r"not valid UTF-16 \(") as info:
        decode_text("t.csv", data, expected="a connection list")
    assert (info.value.line, info.value.expected) == (3, "a connection list")


def test_a_nul_character_in_utf16_is_binary_content() -> None:
    with pytest.raises(IngestError, match=r"binary content \(a NUL character\)") as info:
        decode_text("t.csv", "a\nb\nc\x00d\n".encode("utf-16"), expected="x")
    assert info.value.line == 3


def test_a_bom_inside_the_file_is_removed_with_a_warning() -> None:
    joined = TEXT.encode("utf-8-sig") + "ID000046\tF1500.2\t6503373\r\n".encode("utf-8-sig")
    with pytest.warns(IngestWarning, match=r"byte-order mark inside the file .*; removed") as caught:
        text = decode_text("t.wri", joined, expected="x")
    assert "\ufeff" not in text
    assert text.splitlines()[3] == "ID000046\tF1500.2\t6503373"
    warning = next(w.message for w in caught if isinstance(w.message, IngestWarning))
    assert warning.line == 4


def test_joined_id_tables_keep_the_second_tables_first_id(tmp_path: Path) -> None:
    path = tmp_path / "joined.wri"
    first = (IEMA / "ids.wri").read_bytes()
    path.write_bytes(b"\xef\xbb\xbf" + first + b"\xef\xbb\xbfID009999\tF9999.1\t6503372\r\n")
    with pytest.warns(IngestWarning, match="byte-order mark inside the file"):
        entries = read_wri(path)
    assert entries[-1].cad_id == "ID009999"
    assert entries[-1].line == first.count(b"\n") + 1
    assert entries[:-1] == read_wri(IEMA / "ids.wri")


def test_sniffable_head() -> None:
    head = "N. Pagina\tZona\tComponente:pin".encode("utf-16")
    assert sniffable_head(head) == b"N. Pagina\tZona\tComponente:pin"
    assert sniffable_head(head[:-1]) == b"N. Pagina\tZona\tComponente:pi"  # cut inside a unit
    assert sniffable_head(head[2:]) == b"N. Pagina\tZona\tComponente:pin"  # LE without the BOM
    plain = b"N. Pagina\tZona\tComponente:pin"
    assert sniffable_head(plain) is plain
    assert sniffable_head(b"PK\x03\x04\x14\x00\x06\x00") == b"PK\x03\x04\x14\x00\x06\x00"


# --- whole readers, as exported in UTF-16 --------------------------------------------------------------


def test_lista_cablaggio_saved_as_unicode_text_reads_like_utf8(tmp_path: Path) -> None:
    # Excel's "Unicode Text" and EPLAN's "Unicode" exports: UTF-16 LE with its BOM, CRLF.
    source = IEMA / "lista-cablaggio.csv"
    text = source.read_text(encoding="utf-8").replace("\r\n", "\n").replace("\n", "\r\n")
    path = tmp_path / "lista.csv"
    path.write_bytes(text.encode("utf-16"))
    assert sniff_kind(path) == "connection-list"
    records = _quiet(read_connection_list, path)
    assert records == read_connection_list(source)
    assert len(records) > 60


def test_component_models_in_utf16_read_like_utf8(tmp_path: Path) -> None:
    source = IEMA / "components.xml"
    text = source.read_text(encoding="utf-8").replace('encoding="UTF-8"', 'encoding="UTF-16"')
    path = tmp_path / "models.xml"
    path.write_bytes(text.encode("utf-16"))
    assert sniff_kind(path) == "component-model"
    models = _quiet(read_component_models, path)
    assert models == read_component_models(source)


def _in_utf16(source: Path, target: Path, codec: str = "utf-16") -> Path:
    text = source.read_text(encoding="utf-8").replace('encoding="UTF-8"', 'encoding="UTF-16"')
    target.write_bytes(text.encode(codec))
    return target


def _geometry(item: SceneItem) -> tuple[object, ...]:
    mesh = None if item.mesh is None else (item.mesh.vertices.tolist(), item.mesh.faces.tolist())
    return (item.item_id, item.parent_id, item.translation, item.rotation, item.bbox_min, item.bbox_max, mesh)


# With its BOM, and without (then little- or big-endian as the NULs say, with a warning).
CODECS = ["utf-16", "utf-16-le", "utf-16-be"]


def _read(codec: str, read, path: Path):  # type: ignore[no-untyped-def]
    if codec == "utf-16":
        return _quiet(read, path)
    with pytest.warns(IngestWarning, match="UTF-16 without a byte-order mark"):
        return read(path)


@pytest.mark.parametrize("codec", CODECS)
def test_x3d_in_utf16_reads_like_utf8(tmp_path: Path, codec: str) -> None:
    shutil.copytree(IEMA / "parts", tmp_path / "parts")  # the scene's Inline files, left in UTF-8
    path = _in_utf16(IEMA / "scene.x3d", tmp_path / "scene.x3d", codec)
    assert sniff_kind(path) == "x3d"
    items = _read(codec, read_x3d, path)
    expected = read_x3d(IEMA / "scene.x3d")
    assert [(i.line, *_geometry(i)) for i in items] == [(i.line, *_geometry(i)) for i in expected]
    assert len(items) > 40


@pytest.mark.parametrize("codec", CODECS)
def test_kbl_in_utf16_reads_like_utf8(tmp_path: Path, codec: str) -> None:
    path = _in_utf16(KBL_SAMPLE, tmp_path / "h.kbl", codec)
    assert sniff_kind(path) == "kbl"
    assert _read(codec, read_kbl, path) == read_kbl(KBL_SAMPLE)


def test_an_entity_in_utf16_xml_is_still_refused(tmp_path: Path) -> None:
    path = tmp_path / "scene.x3d"
    xml = (
        '<?xml version="1.0" encoding="UTF-16"?>\n<!DOCTYPE X3D [<!ENTITY e SYSTEM "file:///etc/hostname">]>\n'
        '<X3D><Scene><Transform DEF="ID&e;"/></Scene></X3D>'
    )
    path.write_bytes(xml.encode("utf-16"))
    with pytest.raises(IngestError, match=r"<!ENTITY> is not allowed in X3D") as info:
        read_x3d(path)
    assert info.value.line == 2
