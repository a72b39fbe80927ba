"""What a file's read hands back is bounded by the file (``CADKG_READ_RATIO``): a build, and
``load_files``, past it stop with one line naming the file and the setting, and the store they
would have changed stays as it was, generation and bytes."""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from cadkg.generations import read_pointer
from cadkg.limited.limits import DEFAULT_READ_RATIO, READ_RATIO_ALLOWANCE, read_limits
from tests.conftest import EXAMPLES, ROOT, run_capped, synthetic_manifest

CADKG = [sys.executable, "-m", "cadkg.cli"]
# Every case finishes in a few seconds on an idle machine; a loaded 2-core one takes several
# times that. Past the cap the test fails and the whole process group is killed.
CAP = 180.0


def _env(ratio: int) -> dict[str, str]:
    return {**os.environ, "PYTHONPATH": str(ROOT / "src"), "CADKG_READ_RATIO": str(ratio)}


def _state(store: Path) -> tuple[str | None, dict[str, str]]:
    """The live generation and the digest of every file the store directory holds."""
    digests = {
        str(path.relative_to(store)): hashlib.sha256(path.read_bytes()).hexdigest()
        for path in sorted(store.rglob("*"))
        if path.is_file()
    }
    return read_pointer(store), digests


def _build(manifest: Path, store: Path, ratio: int) -> subprocess.CompletedProcess[str]:
    command = [*CADKG, "build", str(manifest), "--store", str(store)]
    return run_capped(command, cwd=ROOT, cap=CAP, env=_env(ratio))


def _hoses(path: Path, rows: int) -> Path:
    lines = ["product,diameter_mm,length_m,material,bend_radius_mm"]
    lines += [f"HX-{i:07d},{8 + i % 40},{1 + i % 9}.5,EPDM,{80 + i % 50}" for i in range(rows)]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def _refused(result: subprocess.CompletedProcess[str], name: str) -> str:
    assert result.returncode == 2, (result.returncode, result.stdout, result.stderr)
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, lines
    line = lines[0]
    assert name in line and "CADKG_READ_RATIO" in line and "per byte of the file" in line, line
    return line


def test_the_default_ratio_is_documented_and_counts_the_file() -> None:
    hoses = EXAMPLES / "enki-hose" / "hoses.csv"
    limits = read_limits(hoses)
    assert limits.ratio == DEFAULT_READ_RATIO
    assert limits.output == DEFAULT_READ_RATIO * hoses.stat().st_size + READ_RATIO_ALLOWANCE
    text = (ROOT / "docs" / "server.md").read_text(encoding="utf-8")
    assert "CADKG_READ_RATIO" in text and f"is {DEFAULT_READ_RATIO} bytes" in text


@pytest.mark.slow
@pytest.mark.parametrize(
    ("what", "ratio"),
    [
        # A hose list maps to about 25 bytes of N-Triples a byte; a WRI ID table to about 45.
        ("hose", 12),
        ("wri", 24),
    ],
)
def test_a_big_file_past_the_ratio_is_refused_and_the_store_stays(
    tmp_path: Path, what: str, ratio: int
) -> None:
    if what == "hose":
        cell = tmp_path / "cell"
        shutil.copytree(EXAMPLES / "enki-hose", cell)
        manifest, big = cell / "manifest.toml", cell / "hoses.csv"
    else:
        manifest = synthetic_manifest(tmp_path / "cell", 1_000, cabinet=False)
        big = manifest.parent / "ids.wri"
    store = tmp_path / "store"
    built = _build(manifest, store, ratio)
    assert built.returncode == 0, built.stderr
    before = _state(store)
    if what == "hose":
        _hoses(big, 60_000)
    else:  # the ID table of a cabinet of 100,000 wires: the build stops at it, the first source
        shutil.copy(synthetic_manifest(tmp_path / "big", 100_000, cabinet=False).parent / "ids.wri", big)
    assert big.stat().st_size > 1 << 20
    result = _build(manifest, store, ratio)
    line = _refused(result, big.name)
    assert f"more than {ratio} bytes" in line
    assert _state(store) == before
    # Raised as the line says, the same file builds.
    rebuilt = _build(manifest, store, DEFAULT_READ_RATIO)
    assert rebuilt.returncode == 0, rebuilt.stderr
    assert read_pointer(store) != before[0]


_LOAD = r"""
import json, sys
from pathlib import Path
from cadkg.graph import KnowledgeGraph
from cadkg.services.session import Session
from cadkg.services.table import call

store, path = sys.argv[1:3]
graph = KnowledgeGraph.open(store, read_only=False)
session = Session(graph.cell_model(), kg=graph)
quads = lambda: sorted(graph.serialize("nq").splitlines())
before = quads()
result = call(session, "load_files", {"paths": path})
pins = len(graph.query("SELECT ?p WHERE { ?p a ck:BenchPin }"))
print(json.dumps({"success": result.success, "message": result.message, "pins": pins,
                  "same": quads() == before, "quads": len(before)}))
"""


def test_load_files_past_the_ratio_changes_nothing(tmp_path: Path) -> None:
    store = tmp_path / "store"
    env = _env(4)
    built = _build(EXAMPLES / "elimco-bench" / "manifest.toml", store, 4)
    assert built.returncode == 0, built.stderr
    generation = read_pointer(store)
    # The example's pins, which its routes name, and 30,000 more.
    text = (EXAMPLES / "elimco-bench" / "pin_info.xml").read_text(encoding="utf-8")
    pin = '  <pin name="P{0:06d}" role="intermediate" x="{0}" y="{1}"/>\n'
    extra = "".join(pin.format(i, i % 977) for i in range(30_000))
    big = tmp_path / "pin_info.xml"
    big.write_text(text.replace("</pin_info>", extra + "</pin_info>"), encoding="utf-8")
    result = run_capped([sys.executable, "-c", _LOAD, str(store), str(big)], cwd=ROOT, cap=CAP, env=env)
    assert result.returncode == 0, result.stderr
    answer = json.loads(result.stdout.strip().splitlines()[-1])
    assert answer["success"] is False, answer
    message = answer["message"]
    assert str(big) in message and "CADKG_READ_RATIO" in message and "\n" not in message, message
    assert answer["pins"] == 6
    # The store opened for writing is RocksDB's to touch (its log, its manifest): what it
    # serves, every quad, and its generation are what stay.
    assert answer["same"] is True and answer["quads"] > 400, answer
    assert read_pointer(store) == generation


def test_a_reload_past_the_ratio_keeps_the_cell_served(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import httpx

    from cadkg.graph import KnowledgeGraph
    from cadkg.server import Settings
    from tests.server.serving import serving

    cell = tmp_path / "cell"
    shutil.copytree(EXAMPLES / "enki-hose", cell)
    monkeypatch.setenv("CADKG_READ_RATIO", "12")
    hoses = "SELECT (COUNT(?h) AS ?n) WHERE { ?h ck:diameterM ?d }"

    def count(base: str) -> str:
        answer = httpx.get(
            f"{base}/sparql", params={"query": hoses}, headers={"Accept": "application/sparql-results+json"}
        )
        return str(answer.json()["results"]["bindings"][0]["n"]["value"])

    settings = Settings(token="t0ken", watch_seconds=0)
    with serving(lambda: KnowledgeGraph.build(cell / "manifest.toml"), settings) as base:
        assert count(base) == "3"
        _hoses(cell / "hoses.csv", 60_000)
        response = httpx.post(f"{base}/reload", headers={"Authorization": "Bearer t0ken"}, timeout=CAP)
        assert response.status_code != 200
        error = response.json()["error"]
        assert "hoses.csv" in error and "CADKG_READ_RATIO" in error and "\n" not in error, error
        assert count(base) == "3"
