"""Stores the plan tests change: built once per module, copied for each test that writes."""

from __future__ import annotations

import shutil
from pathlib import Path

from cadkg.graph import KnowledgeGraph
from cadkg.plan.cell import store_plan


def built(manifest: Path, store: Path, planned: bool = False) -> Path:
    """``manifest`` built into ``store`` (with its plan stored when ``planned``)."""
    with KnowledgeGraph.build(manifest, store) as kg:
        if planned:
            store_plan(kg)
    return store


def copied(store: Path, target: Path) -> Path:
    """A copy of ``store`` (its generations' hard links kept as links) at ``target``."""
    shutil.copytree(store, target, symlinks=True)
    return target
