"""Input files that would take gigabytes are refused in one line, their reading held to the limit.

Every variant is read in a process of its own, as a build reads it (``read_source``: the
sniff when no kind is given, then the reader in a child under the read limit); that process
reports its own peak and its children's, so the test process's size hides nothing and adds
nothing (its own peak is read from ``VmHWM``, which starts anew at exec, where ``ru_maxrss``
would carry over the test runner's).
"""

from __future__ import annotations

import json
import os
import random
import sys
from pathlib import Path

import pytest

from tests.conftest import synthetic_manifest
from tests.ingest.workbooks import run_child
from tests.security.ingest_bombs import BOMBS

# Low, so that the variants cost the shared machine little; the default is 1024.
LIMIT = 384
VARIANTS = 4
_MEASURE = """
import json, resource, sys
from pathlib import Path
from cadkg.errors import CadkgError
from cadkg.mapping.pipeline import read_source
path, kind, profile = sys.argv[1], sys.argv[2] or None, sys.argv[3]
try:
    data = read_source(Path(path), "f", kind, "https://example.org/bomb/", profile=profile)
    message = f"read {data.report.records} records"
except CadkgError as err:
    message = str(err)
# Not RUSAGE_SELF: Linux keeps ru_maxrss across exec, so it would be at least the size of the
# process that started this one (the test runner); VmHWM is this program's own peak.
with open("/proc/self/status", "rb") as status:
    peak = next(int(line.split()[1]) for line in status if line.startswith(b"VmHWM:"))
print(json.dumps({
    "message": message,
    "self": peak >> 10,
    "children": resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss >> 10,
}))
"""


def measure(
    path: Path, kind: str | None, profile: str, limit: int = LIMIT, timeout: float = 300
) -> dict[str, object]:
    """What reading ``path`` in a fresh process gave: its message and peaks in MiB."""
    command = [sys.executable, "-c", _MEASURE, str(path), kind or "", profile]
    env = {**os.environ, "CADKG_READ_LIMIT_MIB": str(limit)}
    out = run_child(command, timeout, f"reading {path.name}", env)
    found: dict[str, object] = json.loads(out.splitlines()[-1])
    return found


@pytest.mark.parametrize("seed", range(VARIANTS))
@pytest.mark.parametrize("name", sorted(BOMBS))
def test_a_bomb_is_refused_in_one_line_within_the_limit(tmp_path: Path, name: str, seed: int) -> None:
    path, kind, profile = BOMBS[name](tmp_path, random.Random(f"{name}-{seed}"))
    found = measure(path, kind, profile)
    message = str(found["message"])
    assert message.startswith(f"{path}"), message
    assert "\n" not in message and not message.startswith("read "), message
    # The process that asked stays small; the child that read may use its own size and the limit.
    assert int(str(found["self"])) < LIMIT, found
    assert int(str(found["children"])) < int(str(found["self"])) + LIMIT + 32, found


@pytest.mark.parametrize("name", ["xlsx-far-cell", "xlsx-shared-string", "ods-repeated-text"])
def test_a_workbook_bomb_is_refused_when_only_its_content_tells_its_kind(tmp_path: Path, name: str) -> None:
    # The sniff reads the workbook's first rows: it goes through the same child.
    path, _, profile = BOMBS[name](tmp_path, random.Random(name))
    found = measure(path, None, profile)
    assert str(found["message"]).startswith(f"{path}"), found
    assert int(str(found["self"])) < LIMIT, found


def test_what_no_scan_recognises_is_held_by_the_limit(tmp_path: Path) -> None:
    # A sound connection list of 20,000 wires read under a limit it cannot be read in: the
    # reader fails in the child, and the caller gets the line whatever the bytes were.
    listing = synthetic_manifest(tmp_path, 20_000, cabinet=False).parent / "lista-cablaggio.csv"
    found = measure(listing, "connection-list", "iema", limit=4)
    assert found["message"] == f"{listing}: needs more than 4 MiB to read (limit set by CADKG_READ_LIMIT_MIB)"
    assert measure(listing, "connection-list", "iema")["message"] == "read 20001 records"


def test_a_text_export_is_read_a_row_at_a_time(tmp_path: Path) -> None:
    # A million rows were 147 bytes of memory a byte of file. Now the child holds the file's
    # bytes and its text, splits the rows as they are mapped, and sends the N-Triples on in
    # small chunks; besides, it holds what the mapping mints once per cell (pins, wires): about
    # ten bytes a byte of file and 16 MiB (docs/server.md), so twelve are enough, one is not.
    listing = synthetic_manifest(tmp_path, 40_000, cabinet=False).parent / "lista-cablaggio.csv"
    size = listing.stat().st_size / (1 << 20)
    assert (
        measure(listing, "connection-list", "iema", limit=round(12 * size) + 16)["message"]
        == "read 40001 records"
    )
    refused = measure(listing, "connection-list", "iema", limit=round(size))["message"]
    assert str(refused).endswith("to read (limit set by CADKG_READ_LIMIT_MIB)"), refused
