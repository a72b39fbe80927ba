"""Where the checkout is, for the test helpers that tests/conftest.py itself imports."""

from __future__ import annotations

from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
