"""Paths stay in their root: a name built from file content or a request is opened inside its
root or not at all, checked on the open itself (:mod:`cadkg.confined`).

Names are generated from pieces that have broken path checks before (``..``, ``.``, empty
components, absolute paths, NUL, backslashes, commas, the escape character, links in and out
of the root) and compared with what walking the disk by hand says; an X3D whose ``DEF`` s are
such names is built into a store and writes nothing outside it; ``/api/mesh`` follows no link;
``load_files`` takes a list (commas and all) and reads only inside its root while another
thread swaps a folder for a link out of it.
"""

from __future__ import annotations

import itertools
import os
import random
import stat
import threading
from pathlib import Path

import httpx
import pytest

import cadkg
from cadkg.confined import OutsideRootError, file_name, open_inside, write_files
from cadkg.server import Settings
from cadkg.server.workbench.scene import mesh_bytes
from tests.conftest import EXAMPLES
from tests.server.serving import serving

TOKEN = "t0ken"
AUTH = {"Authorization": f"Bearer {TOKEN}"}
PIECES = ("..", ".", "", "a", "b.stl", "in", "out", "dir", "x,", "~2F", "c\\d", "e\x00", "/")


def _names(count: int, seed: int) -> list[str]:
    rng = random.Random(seed)
    names = {"/".join(rng.choice(PIECES) for _ in range(rng.randint(1, 4))) for _ in range(count)}
    names |= {"/" + n for n in list(names)[:20]}
    names |= {"a", "./a", "dir/b.stl", "dir//b.stl", "dir/./b.stl", "in/b.stl", "out/b.stl", "x,/a"}
    return sorted(names)


def _tree(tmp_path: Path) -> tuple[Path, Path]:
    root, outside = tmp_path / "root", tmp_path / "outside"
    for folder in (root / "dir", outside / "dir"):
        folder.mkdir(parents=True)
        (folder / "b.stl").write_bytes(b"inside" if folder.is_relative_to(root) else b"OUTSIDE")
    (outside / "a").write_bytes(b"OUTSIDE")
    (root / "a").write_bytes(b"inside")
    (root / "in").symlink_to(root / "dir")  # a link, even to inside, is not walked through
    (root / "out").symlink_to(outside / "dir")
    (root / "x,").symlink_to(outside)
    (root / "dir" / "out").symlink_to(outside / "a")
    return root, outside


def _expected(root: Path, name: str) -> bytes | None:
    """What a walk by hand finds: a regular file reached through real folders only."""
    if not name or "\x00" in name or "\\" in name or name.startswith("/"):
        return None
    parts = [p for p in name.split("/") if p not in ("", ".")]
    if not parts or ".." in parts:
        return None
    here = root
    for part in parts:
        here = here / part
        try:
            mode = os.lstat(here).st_mode
        except OSError:
            return None
        if stat.S_ISLNK(mode):
            return None
    return here.read_bytes() if stat.S_ISREG(mode) else None


def test_generated_names_open_exactly_the_files_inside_the_root(tmp_path: Path) -> None:
    root, _ = _tree(tmp_path)
    opened = 0
    for name in _names(400, 34):
        expected = _expected(root, name)
        try:
            fd = open_inside(root, name)
        except OutsideRootError:
            assert expected is None, name
            continue
        with os.fdopen(fd, "rb") as file:
            assert file.read() == expected == b"inside", name
        opened += 1
    assert opened >= 5  # the generator reaches files inside as well as refusals


def test_generated_names_are_written_inside_the_root_or_refused(tmp_path: Path) -> None:
    root, outside = _tree(tmp_path)
    before = sorted((p, p.read_bytes()) for p in outside.rglob("*") if p.is_file())
    written = 0
    for name in _names(300, 35):
        try:
            write_files(root, {name: b"new"})
            written += 1
        except OutsideRootError:
            continue
        assert _expected(root, name) == b"new", name
    assert written >= 5
    assert sorted((p, p.read_bytes()) for p in outside.rglob("*") if p.is_file()) == before


def test_a_name_from_a_file_is_one_component_and_never_two_names_one_file() -> None:
    pieces = ("..", ".", "/", "~", "2F", "~2F", "a", "\\", "\x00", "")
    names = {"".join(p) for n in range(1, 4) for p in itertools.product(pieces, repeat=n)}
    files = [file_name(n) for n in names]
    assert len(set(files)) == len(names)
    assert all("/" not in f and "\\" not in f and f not in ("", ".", "..") for f in files)


def _scene(defs: list[str]) -> str:
    shapes = "".join(
        f'<Transform DEF="{d}" translation="{i} 0 0"><Shape><IndexedTriangleSet index="0 1 2">'
        '<Coordinate point="0 0 0 1 0 0 0 1 0"/></IndexedTriangleSet></Shape></Transform>\n'
        for i, d in enumerate(defs)
    )
    return f'<?xml version="1.0" encoding="UTF-8"?>\n<X3D version="3.3"><Scene>\n{shapes}</Scene></X3D>\n'


def test_a_scene_whose_names_climb_out_builds_a_store_that_keeps_its_meshes_inside(tmp_path: Path) -> None:
    rng = random.Random(36)
    defs = ["../../somewhere/path", "/tmp/absolute", "..", "a/../../b", "x,/y", "~2F", "c\\d"]
    defs += ["/".join(rng.choice(("..", "a", "~", "b,c", ".")) for _ in range(3)) for _ in range(20)]
    defs = sorted(set(defs))
    cell = tmp_path / "deep" / "er" / "cell"
    cell.mkdir(parents=True)
    (cell / "scene.x3d").write_text(_scene(defs).replace("&", "&amp;"), encoding="utf-8")
    (cell / "manifest.toml").write_text(
        '[cell]\nname = "paths"\nprofile = "iema"\nbase_iri = "https://example.org/cell/paths/"\n\n'
        '[[source]]\npath = "scene.x3d"\n',
        encoding="utf-8",
    )
    store = cell / "store"
    outside_before = sorted(p for p in tmp_path.rglob("*") if not p.is_relative_to(store))
    with cadkg.build(cell / "manifest.toml", store) as kg:
        uris = [str(r["uri"]) for r in kg.query("SELECT ?uri WHERE { ?m ck:meshUri ?uri }")]
        assert len(set(uris)) == len(defs)
        for uri in uris:
            assert Path(uri).parent == Path("meshes"), uri
            assert mesh_bytes(kg.files_dir, uri), uri  # each read back from inside the store
    assert sorted(p for p in tmp_path.rglob("*") if not p.is_relative_to(store)) == outside_before
    assert not (tmp_path / "somewhere").exists() and not Path("/tmp/absolute.stl").exists()


def test_api_mesh_follows_no_link_in_the_files_directory(tmp_path: Path) -> None:
    kg = cadkg.build(EXAMPLES / "iema-switchgear" / "manifest.toml")
    files = kg.files_dir
    uri = str(kg.query("SELECT ?uri WHERE { ?m ck:meshUri ?uri } LIMIT 1").rows[0]["uri"])
    outside = tmp_path / "outside"
    outside.mkdir()
    (outside / "secret.stl").write_bytes(b"solid CONFIDENTIAL\nendsolid CONFIDENTIAL\n")
    (files / "meshes" / "linked").symlink_to(outside)
    (files / "meshes" / "file-link.stl").symlink_to(outside / "secret.stl")
    with serving(kg) as base:
        assert httpx.get(f"{base}/api/mesh/{uri}").status_code == 200
        for name in (
            "meshes/linked/secret.stl",
            "meshes/file-link.stl",
            "meshes/../../outside/secret.stl",
            "meshes/%2e%2e/%2e%2e/outside/secret.stl",
            f"{outside}/secret.stl",
            "meshes/linked/../linked/secret.stl",
        ):
            response = httpx.get(f"{base}/api/mesh/{name}")
            assert response.status_code == 404, (name, response.status_code)
            assert b"CONFIDENTIAL" not in response.content


def _pins(directory: Path, x: str) -> Path:
    directory.mkdir(parents=True, exist_ok=True)
    text = (EXAMPLES / "elimco-bench" / "pin_info.xml").read_text(encoding="utf-8")
    path = directory / "pin_info.xml"
    path.write_text(text.replace('x="11680" y="3960"', f'x="{x}" y="3960"'), encoding="utf-8")
    return path


def _pin_x(base: str) -> list[float]:
    query = "SELECT ?x WHERE { ?pin ck:label 'A918VC1A' ; ck:benchX ?x }"
    rows = httpx.get(
        f"{base}/sparql", params={"query": query}, headers={"Accept": "application/sparql-results+json"}
    )
    return sorted(float(r["x"]["value"]) for r in rows.json()["results"]["bindings"])


def test_load_files_takes_a_list_and_a_comma_is_part_of_a_name(tmp_path: Path) -> None:
    root, outside = tmp_path / "root", tmp_path / "outside"
    _pins(root / "a,", "55000")
    _pins(outside / "etc", "99000")
    (root / "x,").symlink_to(outside)
    settings = Settings(allow_update=True, token=TOKEN, files_root=root, watch_seconds=0)
    with serving(lambda: cadkg.build(EXAMPLES / "elimco-bench" / "manifest.toml"), settings) as base:
        load = f"{base}/api/load_files"
        for given in (["x,/etc/pin_info.xml"], "x,/etc/pin_info.xml", [f"{root}/x,/etc/pin_info.xml"]):
            refused = httpx.post(load, json={"paths": given}, headers=AUTH)
            assert refused.status_code == 403, refused.text
        assert _pin_x(base) == [11680.0]
        loaded = httpx.post(load, json={"paths": ["a,/pin_info.xml"]}, headers=AUTH)
        assert loaded.status_code == 200 and loaded.json()["success"] is True, loaded.text
        assert _pin_x(base) == [55000.0]
        assert str(tmp_path) not in loaded.text and "cadkg-load-" not in loaded.text
        listed = httpx.post(f"{base}/api/get_pin_positions", json={"use_centroid": ["true"]})
        assert listed.status_code == 400 and "not a list" in listed.text


@pytest.mark.slow
def test_load_files_reads_inside_its_root_while_a_folder_is_swapped_for_a_link(tmp_path: Path) -> None:
    root, outside = tmp_path / "root", tmp_path / "outside"
    _pins(root / "bench", "55000")
    _pins(outside, "99000")
    stop = threading.Event()
    swaps = 0

    def swap() -> None:
        nonlocal swaps
        while not stop.is_set():
            bench = root / "bench"
            bench.rename(root / "bench-real")
            bench.symlink_to(outside)
            stop.wait(0.002)
            bench.unlink()
            (root / "bench-real").rename(bench)
            swaps += 1
            stop.wait(0.002)

    settings = Settings(allow_update=True, token=TOKEN, files_root=root, watch_seconds=0)
    with serving(lambda: cadkg.build(EXAMPLES / "elimco-bench" / "manifest.toml"), settings) as base:
        swapper = threading.Thread(target=swap, daemon=True)
        swapper.start()
        outcomes = []
        try:
            for _ in range(40):
                response = httpx.post(
                    f"{base}/api/load_files", json={"paths": "bench/pin_info.xml"}, headers=AUTH, timeout=120
                )
                outcomes.append(response.status_code)
                assert response.status_code in (200, 403), response.text
                assert _pin_x(base) in ([11680.0], [55000.0])  # never the file outside
        finally:
            stop.set()
            swapper.join(10)
        assert swaps > 40 and 200 in outcomes, (swaps, outcomes)
