"""The items along a terminal strip, matched with the rows of its terminal diagram
(:mod:`cadkg.usecases.iema.terminal_diagram` reads them): apart from the reader, so deriving a
cell does not import the workbook readers."""

from __future__ import annotations

from collections.abc import Iterable

__all__ = ["items_along"]

# Rows of a terminal diagram that stand for an item along the strip; an end row takes the
# strip's next item when the WRI table has one left (its second end stop), else none.
_OWN_ITEM = frozenset({"start", "division", "terminal", "accessory", "end"})


def items_along(
    rows: list[tuple[int, str, str | None]], items: Iterable[str]
) -> list[tuple[int, str, str | None]]:
    """(position, item, terminal) along a strip: its diagram rows matched in order with its items."""
    left = iter(items)
    slots: list[tuple[int, str, str | None]] = []
    placed = 0
    for _, kind, terminal in rows:
        if kind == "floor" and slots:
            slots.append((slots[-1][0], slots[-1][1], terminal))
        elif kind in _OWN_ITEM and (item := next(left, None)) is not None:
            placed += 1
            slots.append((placed, item, terminal if kind == "terminal" else None))
    return slots
