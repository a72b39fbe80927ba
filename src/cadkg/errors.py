"""The one exception hierarchy of cadkg.

Every error a user can cause derives from :class:`CadkgError`. Ingest errors carry
where the problem is (file and line, or ``sheet!cell``), what was found and what
was expected, so the command line can print one clear line instead of a traceback.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, cast

__all__ = [
    "CadkgError",
    "IngestError",
    "IngestWarning",
    "LimitError",
    "ManifestError",
    "MemoryLimitError",
    "NotFound",
    "QueryError",
    "ReadLimitError",
    "RegistryError",
    "StoreError",
    "TimeLimitError",
    "UnknownTermError",
    "format_location",
]


def format_location(path: str | Path | None, line: int | None = None, cell: str | None = None) -> str:
    """``file:line`` or ``file:Sheet!A12`` or just ``file``; empty when nothing is known."""
    where = str(path) if path is not None else ""
    if cell is not None:
        return f"{where}:{cell}" if where else cell
    if line is not None:
        return f"{where}:{line}" if where else f"line {line}"
    return where


def _one_line(text: str) -> str:
    lines = text.splitlines()
    return text if len(lines) <= 1 else " ".join(line.strip() for line in lines if line.strip())


class CadkgError(Exception):
    """Root of every error cadkg raises on purpose."""


def _restore(cls: type[BaseException], args: tuple[object, ...], state: dict[str, object]) -> BaseException:
    made = cls.__new__(cls, *args)
    made.args = args
    made.__dict__.update(state)
    return made


class _Located:
    """Mixin of an error or a warning at a place in a file, formatted
    ``file:line: message (found ..., expected ...)``."""

    path: str | None
    line: int | None
    cell: str | None
    found: str | None
    expected: str | None
    reason: str

    def __init__(
        self,
        path: str | Path | None,
        reason: str,
        *,
        line: int | None = None,
        cell: str | None = None,
        found: object | None = None,
        expected: str | None = None,
    ) -> None:
        # Mixed into an exception or a warning, whose constructor takes the message.
        cast(Any, super()).__init__(self._setup(path, reason, line, cell, found, expected))

    def _setup(
        self,
        path: str | Path | None,
        reason: str,
        line: int | None,
        cell: str | None,
        found: object | None,
        expected: str | None,
    ) -> str:
        self.path = str(path) if path is not None else None
        self.line = line
        self.cell = cell
        self.found = None if found is None else str(found)
        # A reason quoted from a library may run over several lines; an error is printed as one.
        reason = _one_line(reason)
        expected = _one_line(expected) if expected else expected
        self.expected = expected
        self.reason = reason
        text = reason
        details = []
        if found is not None:
            details.append(f"found {self.found!r}")
        if expected:
            details.append(f"expected {expected}")
        if details:
            text += " (" + ", ".join(details) + ")"
        where = format_location(self.path, line, cell)
        return f"{where}: {text}" if where else text

    def __reduce__(self) -> tuple[object, ...]:
        # Pickled as made, not through __init__: files are read in a child process.
        return (_restore, (type(self), getattr(self, "args", ()), dict(self.__dict__)))


class IngestError(_Located, CadkgError):
    """An input file could not be read into records."""


class ManifestError(IngestError):
    """The cell manifest is malformed (unknown key, wrong type, missing file ...)."""


class IngestWarning(_Located, UserWarning):
    """Something in an input file was read under a documented assumption."""


class StoreError(CadkgError):
    """The store directory is missing, locked, or not a cadkg store."""


class QueryError(CadkgError):
    """A SPARQL query is malformed, names an unknown query, or lacks a parameter."""


class LimitError(CadkgError):
    """Untrusted work (reading a file, evaluating a query) stopped at one of its limits.

    ``limit`` says which: ``"memory"``, ``"cpu"`` (CPU time) or ``"wall"`` (time). The message
    names the file or the query, the limit and the setting that raises it (see
    :mod:`cadkg.limited`).
    """

    limit: str = "wall"


class TimeLimitError(LimitError):
    """A query or request ran past its time limit (and was stopped)."""


class MemoryLimitError(LimitError, QueryError):
    """A query needed more memory than a query may take (and was stopped)."""

    limit = "memory"


class ReadLimitError(IngestError, LimitError):
    """An input file needed more memory, CPU time or time to read than a file may take."""

    def __init__(self, path: str | Path | None, reason: str, *, limit: str) -> None:
        super().__init__(path, reason)
        self.limit = limit


class StateError(CadkgError):
    """A request the served cell cannot take as it is: a reload of a graph handed in, which it
    has no way to open again."""


class NotFound(CadkgError):  # noqa: N818 - the name the design documents
    """A label, wire or other named thing is not in the graph."""


class RegistryError(CadkgError, ValueError):
    """A reader, service or use case that cannot be registered: a name taken twice, a use case
    that does not load."""


class UnknownTermError(CadkgError, AttributeError):
    """A term is not defined in the cadkg ontology (a misspelt term)."""
