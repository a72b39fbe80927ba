"""The read limit from the outside: the command's one line, its setting, and a server that
stays up when ``load_files`` is handed a bomb."""

from __future__ import annotations

import os
import random
import resource
import shutil
import subprocess
import sys
from pathlib import Path

import httpx
import pytest

from cadkg.errors import IngestError
from cadkg.limited import read_limited
from tests.conftest import EXAMPLES, ROOT
from tests.security.ingest_bombs import BOMBS
from tests.server.serving import cadkg_serve

CADKG = [sys.executable, "-m", "cadkg.cli"]
TOKEN = "t0ken"


def _manifest(directory: Path, source: Path, kind: str) -> Path:
    manifest = directory / "manifest.toml"
    manifest.write_text(
        f'[cell]\nname = "bomb"\nprofile = "vw"\nbase_iri = "https://example.org/bomb/"\n\n'
        f'[[source]]\npath = "{source.name}"\nkind = "{kind}"\n'
    )
    return manifest


def _cadkg(
    *args: str | Path, env: dict[str, str], limit_data: int | None = None
) -> subprocess.CompletedProcess[str]:
    def limit() -> None:
        if limit_data is not None:
            resource.setrlimit(resource.RLIMIT_DATA, (limit_data, limit_data))

    return subprocess.run(
        [*CADKG, *map(str, args)],
        capture_output=True,
        text=True,
        cwd=ROOT,
        env=env,
        preexec_fn=limit,
        timeout=300,
        check=False,
    )


def _one_line(result: subprocess.CompletedProcess[str]) -> str:
    assert result.returncode == 2, (result.returncode, result.stdout, result.stderr)
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    return lines[0]


def _sparse(path: Path, size: int) -> Path:
    with path.open("wb") as handle:
        handle.write(
            b'<?xml version="1.0"?>\n<kbl:KBL_container xmlns:kbl="http://www.prostep.org/Car_electric_container/KBL2.3/KBLSchema">'
        )
        handle.truncate(size)
    return path


def test_build_says_what_a_file_needs_and_which_setting_limits_it(tmp_path: Path) -> None:
    source = _sparse(tmp_path / "huge.kbl", 3 << 30)
    manifest = _manifest(tmp_path, source, "kbl")
    env = {**dict(os.environ), "CADKG_READ_LIMIT_MIB": "512"}
    line = _one_line(_cadkg("build", manifest, "--store", tmp_path / "store", env=env))
    assert (
        line == f"cadkg: error: {source}: needs more than 512 MiB to read (limit set by CADKG_READ_LIMIT_MIB)"
    )
    env["CADKG_READ_LIMIT_MIB"] = "lots"
    line = _one_line(_cadkg("build", manifest, "--store", tmp_path / "store", env=env))
    assert line == "cadkg: error: CADKG_READ_LIMIT_MIB='lots': expected a whole number of MiB (0: no limit)"


def test_an_out_of_memory_error_without_text_still_says_what_happened(tmp_path: Path) -> None:
    # Read in the command's own process (limit 0) under a data limit of its own: Python's
    # MemoryError has no text, and the line must not end at "error: ".
    source = _sparse(tmp_path / "huge.kbl", 3 << 30)
    manifest = _manifest(tmp_path, source, "kbl")
    env = {**dict(os.environ), "CADKG_READ_LIMIT_MIB": "0"}
    line = _one_line(_cadkg("build", manifest, "--store", tmp_path / "store", env=env, limit_data=1 << 30))
    assert line.startswith("cadkg: error: out of memory"), line


def _aborts() -> list[int]:
    os.abort()


def _allocates() -> list[bytes]:
    return [bytes(64 << 30)]


@pytest.mark.parametrize("read", [_aborts, _allocates], ids=["native abort", "MemoryError"])
def test_a_reader_that_runs_out_of_memory_ends_its_child_not_the_caller(read: object) -> None:
    # Unit check beside the real files above: how the child's end is told to the caller.
    with pytest.raises(IngestError) as info:
        list(read_limited("f.xlsx", read))  # type: ignore[arg-type]
    assert str(info.value) == "f.xlsx: needs more than 1,024 MiB to read (limit set by CADKG_READ_LIMIT_MIB)"


def test_the_reader_s_own_errors_and_warnings_come_back(tmp_path: Path) -> None:
    broken = tmp_path / "pin_info.xml"
    broken.write_text("<pin_info><pin>")
    with pytest.raises(IngestError) as info:
        from cadkg.registry import reader_for

        list(read_limited(broken, reader_for("pin-info").read, broken))
    assert info.value.path == str(broken) and info.value.line is not None


def test_load_files_refuses_a_bomb_and_the_server_stays_up(tmp_path: Path) -> None:
    root = tmp_path / "files"
    root.mkdir()
    shutil.copy(EXAMPLES / "elimco-bench" / "pin_info.xml", root)
    bombs = [
        BOMBS[name](root, random.Random(name))[0]
        for name in ("xlsx-far-cell", "xlsx-shared-string", "ods-repeated-text")
    ]
    manifest = EXAMPLES / "elimco-bench" / "manifest.toml"
    args = ("--allow-update", "--token", TOKEN, "--files-root", str(root), "--watch", "0")
    messages: list[str] = []
    with cadkg_serve(str(manifest), *args) as base:
        for bomb in bombs:
            answer = httpx.post(
                f"{base}/api/load_files",
                json={"paths": bomb.name},
                headers={"Authorization": f"Bearer {TOKEN}"},
                timeout=120,
            )
            body = answer.json()
            assert body.get("success") is False, body
            assert bomb.name in body["message"] and "\n" not in body["message"], body
            messages.append(body["message"])
        assert httpx.get(f"{base}/api/info", timeout=10).status_code == 200
        # The same process still loads a sound file.
        answer = httpx.post(
            f"{base}/api/load_files",
            json={"paths": "pin_info.xml"},
            headers={"Authorization": f"Bearer {TOKEN}"},
            timeout=120,
        )
        assert answer.json()["success"] is True, answer.text
