"""The reader registry: kinds, suffix and content sniffing, and errors every reader must raise."""

from __future__ import annotations

import random
import warnings
from pathlib import Path

import pytest

import cadkg.registry as registry
from cadkg.errors import IngestError, IngestWarning, RegistryError
from cadkg.ingest.eplan.connection_files import read_connections
from cadkg.ingest.reader import Reader
from cadkg.ingest.sheet import SHEET_SUFFIXES
from cadkg.ingest.wri import read_wri
from cadkg.registry import kinds, reader_for, register, sniff_kind
from cadkg.usecase import UseCase
from tests.toys import toy_derivation

REPO = Path(__file__).resolve().parents[2]
EXAMPLE = REPO / "examples" / "iema-switchgear"

READERS = kinds()
BUILTIN_KINDS = [
    "assignments",
    "bill-of-materials",
    "cable-info",
    "component-list",
    "component-model",
    "connection-list",
    "elimco-cable-list",
    "elvez-components",
    "elvez-definitions",
    "elvez-harnesses",
    "elvez-ids",
    "elvez-mesh",
    "elvez-scene",
    "elvez-sequence",
    "harness-text",
    "hose",
    "kbl",
    "marker-table",
    "parts-management",
    "path-info",
    "pin-info",
    "terminal-diagram",
    "terminal-schema",
    "vec",
    "vrml",
    "wri",
    "x3d",
]
KIND_IDS = [r.kind for r in READERS]
# Formats that are binary themselves: NUL bytes are theirs to read, not a sign of a wrong file.
BINARY_FORMATS = {"elvez-mesh"}


def test_kinds_lists_the_builtin_readers() -> None:
    assert [r.kind for r in kinds()] == BUILTIN_KINDS
    assert all(isinstance(r, Reader) and r.description for r in kinds())


def test_reader_for() -> None:
    assert reader_for("wri").read is read_wri
    assert reader_for("connection-list").read is read_connections
    assert ".wri" in reader_for("wri").suffixes
    assert {".csv", ".tsv"} <= set(reader_for("connection-list").suffixes)


def test_reader_for_unknown_kind_names_the_known_ones() -> None:
    with pytest.raises(KeyError, match=f"unknown kind 'xlsx'; known kinds: {', '.join(BUILTIN_KINDS)}"):
        reader_for("xlsx")


def test_a_kind_registers_once() -> None:
    with pytest.raises(ValueError, match="'wri' is already registered"):
        register(Reader(kind="wri", suffixes=(".x",), read=read_wri, description="again"))
    assert reader_for("wri").read is read_wri


@pytest.mark.parametrize(
    ("name", "kind"),
    [
        ("ids.wri", "wri"),
        ("connections-fig3.tsv", "connection-list"),
        ("lista-cablaggio.csv", "connection-list"),
    ],
)
def test_sniff_examples(name: str, kind: str) -> None:
    assert sniff_kind(EXAMPLE / name) == kind


@pytest.mark.parametrize("name", ["connections-fig3.tsv", "lista-cablaggio.csv"])
@pytest.mark.parametrize("suffix", [".xyz", ".dat", ""])
def test_sniff_by_content_when_the_suffix_says_nothing(tmp_path: Path, name: str, suffix: str) -> None:
    path = tmp_path / f"export{suffix}"
    path.write_bytes((EXAMPLE / name).read_bytes())
    assert sniff_kind(path) == "connection-list"


def test_sniff_uses_the_given_head_without_reading(tmp_path: Path) -> None:
    missing = tmp_path / "not-there.bin"
    assert sniff_kind(missing, head=b"Component:pin\tComponent:pin\n") == "connection-list"


def test_sniff_unknown_file_names_the_known_kinds(tmp_path: Path) -> None:
    path = tmp_path / "scene.xyz"
    path.write_bytes(b"lorem ipsum dolor\nsit amet\n")
    with pytest.raises(IngestError) as info:
        sniff_kind(path)
    err = info.value
    assert err.path == str(path)
    assert err.found == ".xyz"
    assert err.expected == "a 'kind' in the manifest, one of: " + ", ".join(BUILTIN_KINDS)
    assert ", ".join(BUILTIN_KINDS) in str(err)


def test_sniff_missing_file_is_an_ingest_error(tmp_path: Path) -> None:
    with pytest.raises(IngestError, match="cannot read the file") as info:
        sniff_kind(tmp_path / "gone.xyz")
    assert info.value.path == str(tmp_path / "gone.xyz")


# --- every registered reader -------------------------------------------------------------------------


def _random_bytes(seed: int, size: int, *, nul: bool) -> bytes:
    rnd = random.Random(seed)
    data = bytes(rnd.randrange(1, 256) for _ in range(size))
    return data[:10] + b"\x00" + data[10:] if nul else data


BAD_CONTENT = {
    "empty": b"",
    "whitespace": b" \r\n\t\r\n",
    "bom-only": b"\xef\xbb\xbf",
    "binary-nul": _random_bytes(1, 300, nul=True),
    "zip-header": b"PK\x03\x04" + _random_bytes(2, 300, nul=True),
    "control-chars": bytes(range(1, 9)) * 40,
    "random-no-nul": _random_bytes(3, 300, nul=False),
    "text-garbage": b"lorem ipsum dolor\nsit amet\n" * 5,
    "utf16-bom-only": b"\xff\xfe",
    "utf16-whitespace": " \r\n\t\r\n".encode("utf-16"),
    "utf16-text-garbage": ("lorem ipsum dolor\nsit amet\n" * 5).encode("utf-16"),
    "utf16-odd-length": "lorem ipsum dolor\n".encode("utf-16") + b"\x41",
}


@pytest.mark.parametrize("content_id", list(BAD_CONTENT))
@pytest.mark.parametrize("reader", READERS, ids=KIND_IDS)
def test_reader_rejects_bad_content_with_a_located_error(
    tmp_path: Path, reader: Reader, content_id: str
) -> None:
    path = tmp_path / f"bad{reader.suffixes[0]}"
    path.write_bytes(BAD_CONTENT[content_id])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", IngestWarning)
        with pytest.raises(IngestError) as info:
            reader.read(path)
    err = info.value
    assert err.path == str(path)
    assert str(err).startswith(str(path))
    if content_id in {"empty", "whitespace", "bom-only", "utf16-bom-only", "utf16-whitespace"}:
        assert err.reason == "the file is empty"
    if set(reader.suffixes) <= set(SHEET_SUFFIXES):
        # A reader of workbooks alone reads no text: anything but a workbook is refused as such.
        assert err.reason.startswith(("the file is empty", "not a workbook", "corrupt workbook"))
    elif content_id == "zip-header" and reader.kind in {"connection-list", "bill-of-materials"}:
        # Read by its content: a ZIP archive is a workbook.
        assert err.reason.startswith("corrupt workbook")
    elif content_id in {"binary-nul", "zip-header"} and reader.kind not in BINARY_FORMATS:
        assert err.reason.startswith("binary content (NUL byte at offset")
        assert err.line == 1


@pytest.mark.parametrize("reader", READERS, ids=KIND_IDS)
def test_reader_rejects_a_missing_file_and_a_directory(tmp_path: Path, reader: Reader) -> None:
    for path in (tmp_path / f"gone{reader.suffixes[0]}", tmp_path):
        with pytest.raises(IngestError, match="cannot read the file") as info:
            reader.read(path)
        assert info.value.path == str(path)


@pytest.mark.parametrize("reader", READERS, ids=KIND_IDS)
def test_reader_rejects_an_unterminated_quote_over_128_kib(tmp_path: Path, reader: Reader) -> None:
    path = tmp_path / f"quote{reader.suffixes[0]}"
    path.write_bytes(b'"' + b"a" * 200_000)
    with pytest.raises(IngestError) as info:
        reader.read(path)
    assert info.value.path == str(path)


def test_each_profile_derives_by_its_own_derivation_else_by_the_default(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setattr(registry, "_TABLE", None)
    cabinet = registry.derivation("iema")
    assert cabinet is not None and cabinet.default
    # The shipped use cases besides IEMA derive nothing of their own: theirs is the default.
    assert registry.derivation("elvez") is cabinet
    assert registry.derivation("") is cabinet
    assert registry.derivation("no-such-profile") is cabinet
    own = toy_derivation()
    registry.add_use_case(UseCase(name="toy-derives", title="a cell with its own model", derivation=own))
    assert registry.derivation("toy-derives") is own
    assert registry.derivation("iema") is cabinet
    assert registry.derivation("elvez") is cabinet


def test_one_derivation_may_be_the_default(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(registry, "_TABLE", None)
    second = UseCase(name="toy-default", title="a second default", derivation=toy_derivation(default=True))
    with pytest.raises(RegistryError, match="iema and toy-default both derive"):
        registry.add_use_case(second)


def test_a_call_finds_its_service_without_reading_the_registry_again(monkeypatch: pytest.MonkeyPatch) -> None:
    from cadkg.services import table
    from cadkg.services.service import Effect, Service

    monkeypatch.setattr(registry, "_TABLE", None)
    reads: list[str] = []
    services_of = registry.services_of

    def counted(profile: str) -> dict[str, Service]:
        reads.append(profile)
        return services_of(profile)

    monkeypatch.setattr(registry, "services_of", counted)
    first = table.find("cad_service", "iema")
    assert first is not None and first is table.find("cad_service", "iema")
    assert reads == ["iema"]
    # A use case added afterwards is seen: the memo is keyed on the registry's state.
    added = Service(
        "toy_answer",
        "a toy's answer",
        {},
        lambda session, client: 1,
        effect=Effect.READS,
        profile="toy-answers",
    )
    registry.add_use_case(UseCase(name="toy-answers", title="one answer", services=(added,)))
    assert table.find("toy_answer", "toy-answers") == added
    assert table.find("cad_service", "iema") is first
    assert reads == ["iema", "toy-answers", "iema"]
