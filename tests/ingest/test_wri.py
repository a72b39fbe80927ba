"""The WRI ID table reader: examples/iema-switchgear/ids.wri, its older form and the malformed samples."""

from __future__ import annotations

from pathlib import Path

import pytest

from cadkg.errors import IngestError, IngestWarning
from cadkg.ingest.wri import IdEntry, read_wri

REPO = Path(__file__).resolve().parents[2]
EXAMPLE_IDS = REPO / "examples" / "iema-switchgear" / "ids.wri"
# The example's table before it took the real exports' shape: labels with and without prefixes.
IDS = REPO / "tests" / "data" / "iema-old-forms" / "ids.wri"
READERS = REPO / "tests" / "data" / "readers"

FIGURE5 = [
    ("ID000041", "X00005.2", "6013277"),
    ("ID000045", "F1500.1", "6503372"),
    ("ID000046", "F1500.1", "6503373"),
    ("ID000047", "F1500.2", "6503373"),
]
FIGURE5_TEXT = "".join(f"{i}\t{label}\t{code}\r\n" for i, label, code in FIGURE5)


@pytest.fixture(scope="module")
def ids() -> list[IdEntry]:
    return read_wri(IDS)


def by_line(entries: list[IdEntry]) -> dict[int, IdEntry]:
    return {e.line: e for e in entries}


# --- the example, in the real exports' shape ------------------------------------------------------------


def test_example_begins_with_the_root_item_and_writes_every_label_with_its_prefix() -> None:
    entries = read_wri(EXAMPLE_IDS)
    assert len(entries) == 127 and [e.line for e in entries] == list(range(1, 128))
    assert entries[0] == IdEntry("ID000001", "1", "=-1", None, 1)
    assert all(e.raw_label == "=-" + e.label for e in entries)
    assert len({e.label for e in entries}) == 63
    # The same rows as the older form, one line down, labels written =-LABEL; only the ducts differ.
    old = read_wri(IDS)
    assert [(e.cad_id, e.label, e.commercial) for e in old if not e.label.startswith("CN")] == [
        (e.cad_id, e.label, e.commercial) for e in entries[1:] if not e.label.startswith("CN")
    ]
    # Lines move one down for the root row, nine more after the ducts for their points.
    assert [e.line + (1 if e.line < 56 else 10) for e in old if not e.label.startswith("CN")] == [
        e.line for e in entries[1:] if not e.label.startswith("CN")
    ]
    assert by_line(entries)[23] == IdEntry("ID000041", "X00005.2", "=-X00005.2", "6013277", 23)
    assert [e.line for e in entries if e.commercial is None] == [1, 21, 56, *range(58, 75, 2)]


def test_example_ducts_are_written_as_the_real_tables_write_them() -> None:
    # Each duct: its row with a BOCCH... code, then its point, a row of the same label without one
    # (the reference node files a code-less -CN row under the duct of its label).
    entries = read_wri(EXAMPLE_IDS)
    ducts = [(e.line, e.cad_id, e.label, e.commercial) for e in entries if e.label.startswith("CN")]
    sizes = ["60X60"] * 4 + ["40X60"] * 3 + ["25X30", "40X60"]
    assert ducts == [
        row
        for n, size in enumerate(sizes, start=1)
        for row in (
            (55 + 2 * n, f"ID{90 + n:06d}", f"CN{n}", f"BOCCH.{size}G"),
            (56 + 2 * n, f"ID{230 + n:06d}", f"CN{n}", None),
        )
    ]
    # The older form's ducts: the same items with digit codes (CN8 none) and no points.
    old = [(e.cad_id, e.commercial) for e in read_wri(IDS) if e.label.startswith("CN")]
    assert old == [
        (f"ID{90 + n:06d}", code)
        for n, code in enumerate(["6300425"] * 4 + ["6300440"] * 3 + [None, "6300440"], start=1)
    ]


# --- the example's older form ----------------------------------------------------------------------------


def test_example_has_117_entries_on_lines_1_to_117(ids: list[IdEntry]) -> None:
    assert len(ids) == 117
    assert [e.line for e in ids] == list(range(1, 118))
    assert len({e.cad_id for e in ids}) == 117


def test_example_has_62_labels(ids: list[IdEntry]) -> None:
    labels = {e.label for e in ids}
    assert len(labels) == 62
    assert {"F1500.1", "Q0010", "X1500", "X1600", "CN1", "CN8", "X00005.1", "B0040.3"} <= labels
    # With the EPLAN prefixes stripped no label starts with a structure sign.
    assert not [label for label in labels if label[0] in "=+-"]


def test_first_and_last_rows(ids: list[IdEntry]) -> None:
    assert ids[0] == IdEntry("ID000012", "Q0010", "=-Q0010", "6100231", 1)
    assert ids[62] == IdEntry("ID000098", "CN8", "=-CN8", None, 63)
    assert ids[-1] == IdEntry("ID000221", "SSB-10Q1", "-SSB-10Q1", "6503202", 117)


@pytest.mark.parametrize(
    ("line", "cad_id", "label", "commercial"),
    [
        (22, "ID000041", "X00005.2", "6013277"),
        (24, "ID000045", "F1500.1", "6503372"),
        (25, "ID000046", "F1500.1", "6503373"),
        (26, "ID000047", "F1500.2", "6503373"),
    ],
)
def test_figure5_rows(ids: list[IdEntry], line: int, cad_id: str, label: str, commercial: str) -> None:
    assert by_line(ids)[line] == IdEntry(cad_id, label, label, commercial, line)


@pytest.mark.parametrize(
    ("line", "cad_id", "raw_label", "label"),
    [
        (1, "ID000012", "=-Q0010", "Q0010"),
        (5, "ID000018", "-T0020.1", "T0020.1"),
        (23, "ID000043", "-K0060.1", "K0060.1"),
        (30, "ID000052", "=-Q1500.1", "Q1500.1"),
        (58, "ID000093", "=-CN3", "CN3"),
    ],
)
def test_prefixes_are_normalized_and_raw_label_kept(
    ids: list[IdEntry], line: int, cad_id: str, raw_label: str, label: str
) -> None:
    entry = by_line(ids)[line]
    assert (entry.cad_id, entry.raw_label, entry.label) == (cad_id, raw_label, label)


def test_unprefixed_label_has_raw_equal_to_label(ids: list[IdEntry]) -> None:
    entry = by_line(ids)[4]
    assert (entry.cad_id, entry.label, entry.raw_label) == ("ID000016", "F0011.1", "F0011.1")


def test_empty_commercial_code_is_none(ids: list[IdEntry]) -> None:
    # Lines 20, 55 and 63 end in a tab: the code is empty, not ''.
    assert [(e.line, e.cad_id) for e in ids if e.commercial is None] == [
        (20, "ID000039"),
        (55, "ID000085"),
        (63, "ID000098"),
    ]
    assert all(e.commercial for e in ids if e.commercial is not None)


def test_component_made_of_several_items(ids: list[IdEntry]) -> None:
    assert [(e.cad_id, e.commercial) for e in ids if e.label == "F1500.1"] == [
        ("ID000045", "6503372"),
        ("ID000046", "6503373"),
    ]
    # 12 terminals between two end stops; 4 terminals after an end stop, then an end plate.
    assert sum(1 for e in ids if e.label == "X1500") == 14
    assert sum(1 for e in ids if e.label == "X1600") == 6


# --- malformed and unusual samples -------------------------------------------------------------------


@pytest.mark.parametrize(
    ("name", "line", "reason", "found"),
    [
        ("wri-bad-id.wri", 2, "malformed CAD item ID", "41"),
        ("wri-binary.wri", 1, "binary content (NUL byte at offset 0)", None),
        ("wri-empty.wri", None, "the file is empty", None),
    ],
)
def test_malformed_sample_is_a_located_error(
    name: str, line: int | None, reason: str, found: str | None
) -> None:
    with pytest.raises(IngestError) as info:
        read_wri(READERS / name)
    err = info.value
    assert err.path is not None and err.path.endswith(name)
    assert err.line == line
    assert err.reason == reason
    assert err.found == found
    where = f"{name}:{line}: " if line is not None else f"{name}: "
    assert where + reason in str(err)
    assert "Cad ID, Label, Commercial" in str(err) or "ID followed by digits" in str(err)


def test_two_column_row_is_read_with_no_commercial_code() -> None:
    # wri.py documents that a row with an empty code "may then drop the last tab";
    # tests/data/README.md lists this sample among the malformed ones (see the report).
    entries = read_wri(READERS / "wri-two-columns.wri")
    assert [(e.cad_id, e.label, e.commercial, e.line) for e in entries] == [
        ("ID000041", "X00005.2", "6013277", 1),
        ("ID000045", "F1500.1", "6503372", 2),
        ("ID000046", "F1500.1", None, 3),
        ("ID000047", "F1500.2", "6503373", 4),
    ]


def test_bom_sample_reads_like_plain(write) -> None:
    raw = (READERS / "wri-bom.wri").read_bytes()
    assert raw.startswith(b"\xef\xbb\xbf")
    plain = write("plain.wri", raw[3:])
    with_bom = read_wri(READERS / "wri-bom.wri")
    assert with_bom == read_wri(plain)
    assert with_bom == [IdEntry(i, label, label, code, n) for n, (i, label, code) in enumerate(FIGURE5, 1)]
    assert with_bom[0].cad_id == "ID000041"  # no U+FEFF glued to the first ID


def test_latin1_sample_warns_and_decodes_label() -> None:
    with pytest.warns(IngestWarning, match=r"not UTF-8 \(first invalid byte 0xfc\)") as caught:
        entries = read_wri(READERS / "wri-latin1.wri")
    warning = next(w.message for w in caught if isinstance(w.message, IngestWarning))
    assert warning.path is not None and warning.path.endswith("wri-latin1.wri")
    assert warning.line == 1
    assert entries == [
        IdEntry("ID000031", "Lüfter.1", "-Lüfter.1", "6712004", 1),
        IdEntry("ID000033", "B0040.3", "-B0040.3", "6712100", 2),
        IdEntry("ID000041", "X00005.2", "X00005.2", "6013277", 3),
    ]


def test_utf8_file_gives_no_warning(recwarn: pytest.WarningsRecorder) -> None:
    read_wri(IDS)
    assert not [w for w in recwarn if issubclass(w.category, IngestWarning)]


# --- inline samples ----------------------------------------------------------------------------------


def test_header_row_is_skipped(write) -> None:
    path = write("h.wri", "Cad ID\tLabel\tCommercial\r\n" + FIGURE5_TEXT)
    entries = read_wri(path)
    assert [e.line for e in entries] == [2, 3, 4, 5]
    assert [(e.cad_id, e.label, e.commercial) for e in entries] == FIGURE5


def test_header_row_after_data_is_an_error(write) -> None:
    path = write("h2.wri", FIGURE5_TEXT + "Cad ID\tLabel\tCommercial\r\n")
    with pytest.raises(IngestError) as info:
        read_wri(path)
    assert info.value.line == 5
    assert info.value.found == "Cad ID"


def test_duplicate_cad_id_names_both_lines(write) -> None:
    path = write("dup.wri", FIGURE5_TEXT + "ID000045\tF1500.3\t6503372\r\n")
    with pytest.raises(IngestError) as info:
        read_wri(path)
    err = info.value
    assert err.line == 5
    assert "ID000045 given twice (first on line 2)" in err.reason
    assert str(err).startswith(f"{path}:5: ")


@pytest.mark.parametrize(
    ("content", "line", "fields"),
    [
        ("ID000041\tX00005.2\t6013277\textra\r\n", 1, 4),
        (FIGURE5_TEXT + "ID000050\tF1500.3\t6503372\tx\t\r\n", 5, 4),
        ("ID000041;X00005.2;6013277\r\n", 1, 1),
        (FIGURE5_TEXT + "\r\nID000050;F1500.3;6503372\r\n", 6, 1),
    ],
    ids=["4-fields", "4-fields-line-5", "semicolons", "semicolons-after-blank-line"],
)
def test_wrong_field_count(write, content: str, line: int, fields: int) -> None:
    path = write("fields.wri", content)
    with pytest.raises(IngestError) as info:
        read_wri(path)
    err = info.value
    assert err.path == str(path)
    assert err.line == line
    assert err.reason == f"{fields} field(s) in the row"
    assert f"fields.wri:{line}: {fields} field(s) in the row" in str(err)


def test_trailing_empty_fields_and_blank_lines(write) -> None:
    path = write("t.wri", "ID000041\tX00005.2\t6013277\t\t\r\n\r\n  \r\nID000045\t=-F1500.1\t\r\n")
    assert read_wri(path) == [
        IdEntry("ID000041", "X00005.2", "X00005.2", "6013277", 1),
        IdEntry("ID000045", "F1500.1", "=-F1500.1", None, 4),
    ]


def test_lf_line_ends_read_like_crlf(write) -> None:
    path = write("lf.wri", FIGURE5_TEXT.replace("\r\n", "\n"))
    assert read_wri(path) == read_wri(READERS / "wri-bom.wri")


@pytest.mark.parametrize("label", ["", "=-"], ids=["empty", "only-prefixes"])
def test_empty_label_is_an_error(write, label: str) -> None:
    path = write("e.wri", FIGURE5_TEXT + f"ID000050\t{label}\t6503372\r\n")
    with pytest.raises(IngestError) as info:
        read_wri(path)
    assert (info.value.line, info.value.reason) == (5, "empty label")


def test_only_blank_lines_is_an_error(write) -> None:
    with pytest.raises(IngestError) as info:
        read_wri(write("blank.wri", "\r\n \r\n\t\r\n"))
    assert info.value.reason in {"the file is empty", "no ID rows"}


def test_unicode_line_separator_inside_a_cell_does_not_split_the_row(write) -> None:
    path = write("ls.wri", "ID000041\tX00005\u20282\t6013277\r\nID000045\tF1500.1\t6503372\r\n")
    entries = read_wri(path)
    assert [(e.cad_id, e.line) for e in entries] == [("ID000041", 1), ("ID000045", 2)]


def test_a_txt_copy_with_a_bom_is_told_from_a_connection_list(tmp_path: Path) -> None:
    from cadkg.ingest.wri import looks_like_wri
    from cadkg.registry import sniff_kind

    # The cell keeps its WRI table also as .txt, the same rows after a UTF-8 byte-order mark.
    text = "ID000001\t=-PE\t\r\nID000002\t=-CN1\tBOCCH.40X100G\r\nID000041\t=SSB-07Q1\tSIEMENS 5SL4206-8\r\n"
    path = tmp_path / "cabinet_ids.txt"
    path.write_bytes(b"\xef\xbb\xbf" + text.encode())
    assert looks_like_wri(path.read_bytes()) and sniff_kind(path) == "wri"
    first, _, third = read_wri(path)
    assert (first.cad_id, first.label, first.commercial) == ("ID000001", "PE", None)
    assert (third.label, third.raw_label, third.commercial) == ("07Q1", "=SSB-07Q1", "SIEMENS 5SL4206-8")
    assert not looks_like_wri(b"N. Pagina\tZona\tComponente:pin\n")
