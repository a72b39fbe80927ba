from __future__ import annotations

import sys
from pathlib import Path

import cadkg
from tests.conftest import ROOT

sys.path.insert(0, str(ROOT / "benchmarks"))
import synthetic


def test_synthetic_cell_builds_and_validates_clean(tmp_path: Path) -> None:
    manifest = synthetic.write_cell(tmp_path, 300, seed=1)
    kg = cadkg.build(manifest)
    wires = kg.query("SELECT (COUNT(DISTINCT ?w) AS ?n) WHERE { ?w a ck:Wire }").rows[0]["n"]
    assert wires == 300
    assert [f for f in cadkg.validate(kg, shacl=False) if f.severity == "error"] == []
    again = tmp_path / "again"
    synthetic.write_cell(again, 300, seed=1)
    assert (again / "ids.wri").read_bytes() == (tmp_path / "ids.wri").read_bytes()
