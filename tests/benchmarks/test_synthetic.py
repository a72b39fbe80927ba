from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

import cadkg
import cadkg.usecases.iema.cursors as cursors
from cadkg.graph import KnowledgeGraph
from cadkg.services.session import Session
from cadkg.services.table import services_for
from cadkg.usecases.iema import answers as iema
from tests.conftest import ROOT

sys.path.insert(0, str(ROOT / "benchmarks"))
import synthetic

# A benchmark's smoke run: the script itself, at a size, in a new interpreter.
pytestmark = pytest.mark.slow


def test_synthetic_cell_builds_and_validates_clean(tmp_path: Path) -> None:
    manifest = synthetic.write_cell(tmp_path, 300, seed=1)
    kg = cadkg.build(manifest)
    wires = kg.query("SELECT (COUNT(DISTINCT ?w) AS ?n) WHERE { ?w a ck:Wire }").rows[0]["n"]
    assert wires == 300
    assert [f for f in cadkg.validate(kg, shacl=False) if f.severity == "error"] == []
    again = tmp_path / "again"
    synthetic.write_cell(again, 300, seed=1)
    assert (again / "ids.wri").read_bytes() == (tmp_path / "ids.wri").read_bytes()


def test_synthetic_cabinet_has_pin_data_and_rails_in_order(tmp_path: Path) -> None:
    files = synthetic.write_cabinet_files(tmp_path, 60, seed=2)
    kg = KnowledgeGraph.build(files.manifest)
    model = kg.cell_model()
    assert len(model.steps) == 60
    # Only the ends the generator put on a motor outside the cabinet lack pin data.
    assert files.missing_ends
    assert {end for step in model.steps for end in step.missing} == files.missing_ends
    assert all(len(step.keypoints) >= 2 for step in model.steps if not step.missing)
    assert set(files.human_wires) <= {s.wire for s in model.steps if s.performer == "human"}

    session = Session(model)
    scans = []
    while not (scan := cursors.rail_scanner(session)).end:
        scans.append(scan)
    assert [scan.rail for scan in scans] == list(files.rails)
    for scan in scans:
        expected = [label for label in files.rails[scan.rail] if label not in files.human_components]
        assert list(scan.components_label) == expected
        # The rails are not turned in the cabinet frame: along a rail is along x.
        xs = [pose.position[0] for pose in scan.component_poses]
        assert xs == sorted(xs) and len(set(xs)) == len(xs)

    block = files.terminal_blocks[0]
    terminal = iema.get_terminal_data(model, block)
    assert terminal.success and terminal.pins[:2] == ("1:a", "1:b")

    again = synthetic.write_cabinet_files(tmp_path / "again", 60, seed=2)
    for first, second in zip(files.files, again.files, strict=True):
        assert first.read_bytes() == second.read_bytes()


def test_bench_services_quick_prints_a_table() -> None:
    script = ROOT / "benchmarks" / "bench_services.py"
    result = subprocess.run(
        [sys.executable, str(script), "--quick"], capture_output=True, text=True, timeout=120, check=False
    )
    assert result.returncode == 0, result.stderr
    assert "| service | calls | call() p50 µs |" in result.stdout
    for name in (s.name for s in services_for("iema")):
        assert f"| `{name}` | 200 |" in result.stdout
    assert "differs" not in result.stdout  # the SPARQL baseline gave the services' answers
