"""The derived model kept in an on-disk store: read back exactly, used on reopening, never stale."""

from __future__ import annotations

import base64
import json
import struct
from pathlib import Path

import pytest

import cadkg
from cadkg.generations import read_pointer
from cadkg.usecases.iema.derive.cabinet import CellModel, derive_cell
from cadkg.usecases.iema.derive.extract import extract
from cadkg.usecases.iema.derive.persist import dump_model, load_model
from tests.conftest import BAD, EXAMPLES, IEMA, ROOT, synthetic_manifest

MINI = ROOT / "tests" / "data" / "cells" / "mini" / "manifest.toml"
CELLS = [
    IEMA,
    EXAMPLES / "iema-switchgear" / "manifest-vrml.toml",
    MINI,
    BAD,
    EXAMPLES / "elvez-cell" / "manifest.toml",
]


def _derived(kg: cadkg.KnowledgeGraph) -> CellModel:
    return derive_cell(extract(kg))


def _model_file(store: Path) -> Path:
    # The live generation's (the store also keeps the one before, for 'cadkg diff STORE').
    live = read_pointer(store)
    assert live is not None
    return store / live / "cell-model.json"


@pytest.mark.parametrize("manifest", CELLS, ids=lambda p: f"{p.parent.name}/{p.name}")
def test_a_model_reads_back_equal(manifest: Path) -> None:
    model = cadkg.build(manifest).cell_model()
    back = load_model(dump_model(model))
    assert back == model
    # A step's ends are its components' pins, the same objects, as the derivation made them.
    for step in back.steps:
        assert step.origin in back.components[step.origin.label].pins.values()
        assert any(step.origin is pin for pin in back.components[step.origin.label].pins.values())


def test_a_synthetic_cabinet_reads_back_bit_for_bit(tmp_path: Path) -> None:
    model = cadkg.build(synthetic_manifest(tmp_path, 300, cabinet=True)).cell_model()
    assert len(model.steps) == 300
    back = load_model(dump_model(model))
    assert back == model
    # Equal floats, and the same bits: repr gives the shortest text of the exact double.
    assert [repr(c) for p in back.steps[7].keypoints for c in p.position] == [
        repr(c) for p in model.steps[7].keypoints for c in p.position
    ]


def _damaged(data: bytes) -> list[bytes]:
    doc = json.loads(data)
    cases = [b"", b"\x00\xff garbage", data[: len(data) // 2], b"[" * 100_000, b'{"format": 1}']
    for key, value in [
        ("format", 1),
        ("cadkg", "0.0.0"),
        ("numbers", "not base64!"),
        ("numbers", base64.b64encode(b"\x00" * 5).decode()),
        ("frame", 3),
        ("approach_distance", True),
        ("steps", {}),
        ("components", []),
    ]:
        cases.append(json.dumps({**doc, key: value}).encode())
    label = next(iter(doc["components"]))
    for index, value in [(2, -7), (2, 10**9), (2, 1.5), (1, "F1"), (7, 1), (9, "long")]:
        fields = list(doc["components"][label])
        fields[index] = value
        cases.append(json.dumps({**doc, "components": {**doc["components"], label: fields}}).encode())
    step = list(doc["steps"][0])
    step[4] = ["no such label", "1"]
    cases.append(json.dumps({**doc, "steps": [step, *doc["steps"][1:]]}).encode())
    return cases


def test_a_damaged_or_foreign_file_reads_as_nothing() -> None:
    data = dump_model(cadkg.build(IEMA).cell_model())
    cases = _damaged(data)
    assert len(cases) == 20
    for case in cases:
        assert load_model(case) is None


def test_a_store_keeps_its_model_and_reopening_reads_it(tmp_path: Path) -> None:
    store = tmp_path / "store"
    cadkg.build(IEMA, store).close()
    kept = _model_file(store)
    doc = json.loads(kept.read_bytes())
    # Change one number in the file: the reopened store must show it, so it read the file.
    numbers = base64.b64decode(doc["numbers"])
    at = doc["components"]["F1500.1"][4] * 8  # target pose, x
    doctored = numbers[:at] + struct.pack("<d", 12.5) + numbers[at + 8 :]
    kept.write_bytes(json.dumps({**doc, "numbers": base64.b64encode(doctored).decode()}).encode())
    with cadkg.open(store) as kg:
        assert kg.cell_model().components["F1500.1"].target.position[0] == 12.5
        assert _derived(kg).components["F1500.1"].target.position[0] != 12.5


def test_a_damaged_kept_model_is_derived_again(tmp_path: Path) -> None:
    store = tmp_path / "store"
    cadkg.build(IEMA, store).close()
    kept = _model_file(store)
    kept.write_bytes(b'{"format": 1, "cadkg": "')
    with cadkg.open(store) as kg:
        assert kg.cell_model() == _derived(kg)
    assert kept.read_bytes() == b'{"format": 1, "cadkg": "'  # a read-only store writes nothing
    with cadkg.open(store, read_only=False) as kg:
        model = kg.cell_model()
    assert load_model(kept.read_bytes()) == model


def test_changes_to_the_store_replace_the_kept_model(tmp_path: Path) -> None:
    store = tmp_path / "store"
    with cadkg.build(MINI, store) as kg:
        wire = kg.cell_model().steps[0].wire
        assert kg.cell_model().steps[0].performer == "robot"
        kg.assign("wire", wire, "human")
    with cadkg.open(store) as kg:
        assert kg.cell_model().steps[0].performer == "human"
        assert kg.cell_model() == _derived(kg)
    with cadkg.open(store, read_only=False) as kg:
        kg.execute(
            """DELETE { GRAPH ?g { ?c ck:approachDistance ?d } }
               INSERT { GRAPH ?g { ?c ck:approachDistance 0.25e0 } }
               WHERE { GRAPH ?g { ?c a ck:Cell ; ck:approachDistance ?d } }""",
            update=True,
        )
    with cadkg.open(store) as kg:
        # tests/test_store.py: K1's target is the approach distance in front of its front face.
        assert kg.cell_model().components["K1"].target.position[2] == pytest.approx(0.3175)
        assert load_model(_model_file(store).read_bytes()) == _derived(kg)


def test_a_failed_update_leaves_no_stale_model(tmp_path: Path) -> None:
    store = tmp_path / "store"
    cadkg.build(MINI, store).close()
    with cadkg.open(store, read_only=False) as kg, pytest.raises(cadkg.QueryError):
        kg.execute("INSERT DATA { GRAPH <urn:g> { <urn:a> <urn:b> }", update=True)
    with cadkg.open(store) as kg:
        assert kg.cell_model() == _derived(kg)
