"""Damaged copies of every example input: each reads, or fails with a located cadkg error.

The copies are made by seeded mutations (a byte changed, a span cut, a line repeated, a
number or a field replaced by something odd, a workbook's sheet XML damaged), so a failure
here is reproducible from its test id. A case that takes more than a minute fails: padding
a huge row number or expanding a repeat count must be refused, not attempted.
"""

from __future__ import annotations

import io
import random
import re
import shutil
import signal
import warnings
import zipfile
from collections.abc import Iterator
from pathlib import Path
from types import FrameType

import pyoxigraph as ox
import pytest

from cadkg.errors import CadkgError
from cadkg.ingest.manifest import load_manifest
from cadkg.mapping.pipeline import manifest_graph, read_source
from cadkg.registry import sniff_kind

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
MANIFESTS = [
    "iema-switchgear/manifest.toml",
    "iema-switchgear/manifest-vrml.toml",
    "iema-switchgear/manifest-komax.toml",
    "iema-switchgear/manifest-fig3.toml",
    "elvez-cell/manifest.toml",
    "elimco-bench/manifest.toml",
    "vw-harness/manifest.toml",
    "enki-hose/manifest.toml",
]
COPIES = 12
ODD = [
    "",
    "nan",
    "inf",
    "-inf",
    "1e400",
    "-0",
    "1,5,6",
    "abc",
    "１２",
    " 7 ",
    "9" * 5000,
    "\u00b2",
    "1.5.2",
    '"',
    "'",
    "<",
    "&x;",
    "\t",
    ";",
    ":",
    "=-",
    "\u00a0",
    "\ufeff",
    "\x00",
    "1e-400",
    "0x10",
]
_ODD_BYTES = [b"\x00", b"\xff", b'"', b"\t", b"\n", b"<", b"&", b";", b"\r"]
_NUMBER = re.compile(rb"-?\d+(?:[.,]\d+)?(?:[eE][-+]?\d+)?")
_FIELD_END = re.compile(rb'[\t;,"<> =\n]')


def _sources() -> Iterator[tuple[Path, str]]:
    seen = set()
    for name in MANIFESTS:
        manifest = load_manifest(EXAMPLES / name)
        for source in manifest.sources:
            if source.path not in seen:
                seen.add(source.path)
                # The kind of the intact file: a damaged copy is read as what it was.
                yield source.path, source.kind or sniff_kind(source.path)


def _mutate(data: bytes, rng: random.Random) -> bytes:
    n = len(data)
    lines = data.split(b"\n")
    numbers = list(_NUMBER.finditer(data))
    ends = [m.start() for m in _FIELD_END.finditer(data)]
    op = rng.randrange(9)
    if op == 0:
        i = rng.randrange(n)
        return data[:i] + bytes([rng.randrange(256)]) + data[i + 1 :]
    if op == 1:
        i = rng.randrange(n)
        return data[:i] + rng.choice(_ODD_BYTES) + data[i:]
    if op == 2:
        i = rng.randrange(n)
        return data[:i] + data[i + rng.randrange(1, 200) :]
    if op == 3:
        return data[: rng.randrange(n)]
    if op == 4 and len(lines) > 1:
        i = rng.randrange(len(lines))
        return b"\n".join([*lines[: i + 1], lines[i], *lines[i + 1 :]])
    if op == 5 and len(lines) > 1:
        i = rng.randrange(len(lines))
        return b"\n".join(lines[:i] + lines[i + 1 :])
    if op == 6 and numbers:
        m = rng.choice(numbers)
        return data[: m.start()] + rng.choice(ODD).encode() + data[m.end() :]
    if len(ends) > 2:
        k = rng.randrange(len(ends) - 1)
        return data[: ends[k] + 1] + rng.choice(ODD).encode() + data[ends[k + 1] :]
    return data[::-1]


def _intact_archive(data: bytes) -> bool:
    try:
        with zipfile.ZipFile(io.BytesIO(data)) as archive:
            return archive.testzip() is None
    except (zipfile.BadZipFile, ValueError, OSError, EOFError):
        return False


def _mutate_workbook(data: bytes, rng: random.Random) -> bytes:
    archive = zipfile.ZipFile(io.BytesIO(data))
    members = [i for i in archive.infolist() if i.filename.endswith(".xml")]
    sheets = [i for i in members if "sheet" in i.filename or i.filename == "content.xml"] or members
    target = rng.choice(sheets)
    out = io.BytesIO()
    with zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED) as damaged:
        for info in archive.infolist():
            member = archive.read(info)
            damaged.writestr(info, _mutate(member, rng) if info is target else member)
    return out.getvalue()


def _cases() -> Iterator[object]:
    for path, kind in _sources():
        for copy in range(COPIES):
            rel = path.relative_to(EXAMPLES).as_posix()
            yield pytest.param(path, kind, copy, id=f"{rel}#{copy}")


def _too_slow(signum: int, frame: FrameType | None) -> None:
    raise TimeoutError("reading a damaged copy took over a minute")


@pytest.mark.parametrize(("path", "kind", "copy"), list(_cases()))
def test_damaged_copy_reads_or_fails_with_a_cadkg_error(
    tmp_path: Path, path: Path, kind: str, copy: int
) -> None:
    rng = random.Random(f"{path.name}#{copy}")
    data = path.read_bytes()
    workbook = data.startswith(b"PK")
    for _ in range(rng.choice([1, 1, 2, 3])):
        data = _mutate_workbook(data, rng) if workbook and rng.random() > 0.2 else _mutate(data, rng)
        workbook = workbook and _intact_archive(data)
    damaged = tmp_path / path.name
    damaged.write_bytes(data)
    previous = signal.signal(signal.SIGALRM, _too_slow)
    signal.alarm(60)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            read_source(damaged, path.name, kind, "https://example.org/damaged/")
    except CadkgError as err:
        assert str(err).startswith(str(damaged)), "the error names the damaged file first"
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)


@pytest.mark.parametrize(("name", "copy"), [(m, c) for m in MANIFESTS for c in range(COPIES)])
def test_damaged_manifest_loads_or_fails_with_a_cadkg_error(tmp_path: Path, name: str, copy: int) -> None:
    original = EXAMPLES / name
    rng = random.Random(f"{name}#{copy}")
    data = original.read_bytes()
    for _ in range(rng.choice([1, 1, 2])):
        data = _mutate(data, rng)
    # Among the example's files, so the paths it names still resolve.
    cell = shutil.copytree(original.parent, tmp_path / "cell")
    damaged = cell / original.name
    damaged.write_bytes(data)
    try:
        manifest = load_manifest(damaged)
        graph = manifest_graph(manifest)
        # What the manifest states must load as it will in a build.
        ox.Store().load(graph.ntriples, ox.RdfFormat.N_TRIPLES, to_graph=ox.NamedNode(graph.graph))
    except CadkgError as err:
        assert str(err).startswith(str(damaged)), "the error names the damaged manifest first"
