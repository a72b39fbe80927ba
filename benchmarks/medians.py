"""Medians and spreads of repeated runs, as the benchmark reports print them.

A figure a report states is the median of its runs with the lowest and highest beside it,
and a target is "met" only when the median meets it.
"""

from __future__ import annotations

import statistics
from collections.abc import Sequence

__all__ = ["median", "spread", "verdict"]


def median(values: Sequence[float]) -> float:
    return statistics.median(values)


def spread(values: Sequence[float], digits: int = 2, suffix: str = "") -> str:
    """``median (lowest–highest)``, or the one value of a single run."""
    if not values:
        return "—"
    text = f"{median(values):,.{digits}f}{suffix}"
    if len(values) > 1:
        text += f" ({min(values):,.{digits}f}–{max(values):,.{digits}f})"
    return text


def verdict(values: Sequence[float], target: float, *, at_most: bool) -> str:
    """ "met" when the median is within ``target`` (at most, or at least), else "**not met**"."""
    if not values:
        return "—"
    value = median(values)
    return "met" if (value <= target if at_most else value >= target) else "**not met**"
