"""Hose product tables (ENKI): diameter required, length, material and bend radius optional."""

from __future__ import annotations

from collections.abc import Callable
from decimal import Decimal
from pathlib import Path

import pytest

from cadkg.errors import IngestError
from cadkg.registry import sniff_kind
from cadkg.usecases.enki.hose import HoseProduct, looks_like_hose_table, read_hoses
from tests.conftest import EXAMPLES

HOSES = EXAMPLES / "enki-hose" / "hoses.csv"
Write = Callable[[str, str | bytes], Path]


def test_the_example_table() -> None:
    assert read_hoses(HOSES) == [
        HoseProduct("HX-16", 0.016, Decimal("2.5"), "EPDM", 0.08, 2),
        HoseProduct("HX-25", 0.0254, None, "PVC", 0.125, 3),
        HoseProduct("HX-08", 0.008, Decimal("1.2"), "silicone", None, 4),
    ]


def test_units_in_the_header_and_decimal_commas(write: Write) -> None:
    text = "Product;Diameter (m);Length [mm];Bend radius (mm)\nH1;0,02;1500;55,5\n"
    assert read_hoses(write("h.csv", text)) == [HoseProduct("H1", 0.02, Decimal("1.5"), None, 0.0555, 2)]


def test_only_product_and_diameter(write: Write) -> None:
    (hose,) = read_hoses(write("h.csv", "product,diameter_mm\r\nH1,12\r\n"))
    assert (hose.diameter_m, hose.length_m, hose.material, hose.bend_radius_m) == (0.012, None, None, None)


def test_a_value_may_carry_the_column_unit(write: Write) -> None:
    (hose,) = read_hoses(write("h.csv", "product,diameter_mm\nH1,12 mm\n"))
    assert hose.diameter_m == 0.012


@pytest.mark.parametrize(
    ("text", "line", "reason"),
    [
        ("product,diameter\nH1,12\n", 1, "column 'diameter' without its unit"),
        ("product,diameter_mm,colour\nH1,12,red\n", 1, "unknown column 'colour'"),
        ("product,length_m\nH1,2\n", 1, "missing column diameter"),
        ("product,diameter_mm,diameter_m\nH1,12,0.012\n", 1, "two diameter columns"),
        ("product,diameter_mm\n", 1, "no hose after the header"),
        ("product,diameter_mm\nH1,\n", 2, "empty diameter"),
        ("product,diameter_mm\n,12\n", 2, "empty product"),
        ("product,diameter_mm\nH1,-12\n", 2, "not a diameter"),
        ("product,diameter_mm\nH1,12 m\n", 2, "not a diameter"),
        ("product,diameter_mm,bend_radius_mm\nH1,12,abc\n", 2, "not a bend radius"),
        ("product,diameter_mm,length_m\nH1,12,0\n", 2, "not a length"),
        ("product,diameter_mm\nH1,12\nH1,13\n", 3, "product 'H1' given twice (first on line 2)"),
    ],
)
def test_bad_tables(write: Write, text: str, line: int, reason: str) -> None:
    path = write("hoses.csv", text)
    with pytest.raises(IngestError) as info:
        read_hoses(path)
    assert (info.value.line, info.value.reason) == (line, reason)
    assert str(info.value).startswith(f"{path}:{line}: {reason}")


def test_sniffing(tmp_path: Path) -> None:
    assert sniff_kind(HOSES) == "hose"
    assert looks_like_hose_table(b"\xef\xbb\xbfProduct;Diameter (mm)\n")
    assert not looks_like_hose_table(b"product,diameter\n")  # no unit: not claimed
    assert not looks_like_hose_table(b"kind,id,performer\n")
    for name, kind in (
        ("assignments.csv", "assignments"),
        ("component-list.csv", "component-list"),
        ("lista-cablaggio.csv", "connection-list"),
        ("terminals.csv", "terminal-schema"),
    ):
        assert sniff_kind(EXAMPLES / "iema-switchgear" / name) == kind
