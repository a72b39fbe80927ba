"""The columns of a ``SELECT *`` answer in the order the query names its variables.

SPARQL leaves the order of ``SELECT *`` columns to the store, and pyoxigraph sorts them by
name (``?o ?p ?s`` for ``?s ?p ?o``). An engineer reads a table in the order they wrote the
pattern, so the endpoint answers ``SELECT *`` with the variables in the order of their first
appearance in the query; variables the text does not show (none, normally) come last.
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from typing import Any

__all__ = ["star_order", "with_star_order"]

# Comments, strings (long and short), IRIs, variables, words; anything else one character.
_TOKEN = re.compile(
    r"""\#[^\n]*
    |\"\"\"(?:[^"\\]|\\.|"(?!""))*\"\"\"
    |'''(?:[^'\\]|\\.|'(?!''))*'''
    |"(?:[^"\\\n]|\\.)*"
    |'(?:[^'\\\n]|\\.)*'
    |<[^<>"{}|^`\\\x00-\x20]*>
    |[?$](?P<var>[A-Za-z0-9_\u00b7-\uffff]+)
    |(?P<word>[A-Za-z_][\w-]*)
    |\S""",
    re.VERBOSE,
)
_MODIFIERS = {"DISTINCT", "REDUCED"}


def star_order(text: str) -> list[str] | None:
    """The variables of a ``SELECT *`` query in order of first appearance; None for any other query.

    >>> star_order("SELECT * WHERE { ?s ?p ?o }")
    ['s', 'p', 'o']
    >>> star_order("SELECT ?o ?s WHERE { ?s ?p ?o }") is None
    True
    """
    tokens = _TOKEN.finditer(text)
    star = False
    for match in tokens:
        word = (match.group("word") or "").upper()
        if word in ("PREFIX", "BASE") or match.group(0).startswith("#"):
            continue
        if word == "SELECT":
            for after in tokens:
                token = after.group(0)
                if token.startswith("#") or token.upper() in _MODIFIERS:
                    continue
                star = token == "*"
                break
            break
        if word in ("ASK", "CONSTRUCT", "DESCRIBE"):
            return None
    if not star:
        return None
    order: dict[str, None] = {}
    for match in tokens:
        name = match.group("var")
        if name:
            order.setdefault(name, None)
    return list(order)


class _Reordered:
    """SELECT solutions with their columns permuted; read like pyoxigraph's ``QuerySolutions``."""

    def __init__(self, solutions: Any, permutation: list[int]) -> None:
        self._solutions = solutions
        self._permutation = permutation
        self.variables = [solutions.variables[i] for i in permutation]

    def __iter__(self) -> Iterator[tuple[Any, ...]]:
        permutation = self._permutation
        for solution in self._solutions:
            yield tuple(solution[i] for i in permutation)


def with_star_order(result: Any, text: str) -> Any:
    """``result`` with ``SELECT *`` columns in the query's order; any other result as it is."""
    if not hasattr(result, "variables"):
        return result
    order = star_order(text)
    if order is None:
        return result
    names = [v.value for v in result.variables]
    rank = {name: index for index, name in enumerate(order)}
    permutation = sorted(range(len(names)), key=lambda i: (rank.get(names[i], len(rank)), names[i]))
    if permutation == list(range(len(names))):
        return result
    return _Reordered(result, permutation)
