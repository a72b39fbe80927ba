"""The table of readers, keyed by kind and by file suffix, with content sniffing.

Adding a format means writing ``read_<kind>(path) -> records`` and one
:func:`register` call; the manifest, the CLI and ``cadkg kinds`` pick it up.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path

from cadkg.errors import IngestError
from cadkg.ingest.text import sniffable_head

__all__ = ["Reader", "kinds", "reader_for", "register", "sniff_kind"]

Sniffer = Callable[[bytes], bool]


@dataclass(frozen=True)
class Reader:
    """A registered input format."""

    kind: str
    suffixes: tuple[str, ...]
    read: Callable[[str | Path], Sequence[object]]
    description: str
    sniff: Sniffer | None = None
    # Records one by one, for formats big enough that a build should map and load the
    # first rows while the last are still being converted.
    stream: Callable[[str | Path], Iterator[object]] | None = None


_READERS: dict[str, Reader] = {}


def register(reader: Reader) -> Reader:
    """Add a reader to the table; a kind may be registered once."""
    if reader.kind in _READERS:
        raise ValueError(f"reader kind {reader.kind!r} is already registered")
    _READERS[reader.kind] = reader
    return reader


def kinds() -> list[Reader]:
    """Every registered reader, sorted by kind."""
    _load_builtin()
    return sorted(_READERS.values(), key=lambda r: r.kind)


def sniff_kind(path: str | Path, head: bytes | None = None) -> str:
    """The kind of a file from its suffix, or from its first bytes when the suffix is shared.

    Raises
    ------
    IngestError
        When no reader claims the file.
    """
    _load_builtin()
    suffix = Path(path).suffix.lower()
    candidates = [r for r in _READERS.values() if suffix in r.suffixes]
    if len(candidates) == 1:
        return candidates[0].kind
    if head is None:
        try:
            with Path(path).open("rb") as handle:
                head = handle.read(16384)
        except OSError as err:
            raise IngestError(path, f"cannot read the file: {err.strerror}") from err
        except ValueError:  # a NUL byte in a path given by a service caller
            raise IngestError(repr(str(path)), "cannot read the file: a NUL byte in its name") from None
    head = sniffable_head(head)
    sniffed = [r for r in candidates or _READERS.values() if r.sniff is not None and r.sniff(head)]
    if len(sniffed) == 1:
        return sniffed[0].kind
    names = ", ".join(r.kind for r in kinds())
    raise IngestError(
        path,
        "cannot tell the kind of this file from its suffix or content",
        found=suffix or "no suffix",
        expected=f"a 'kind' in the manifest, one of: {names}",
    )


def reader_for(kind: str) -> Reader:
    """The reader registered for ``kind``; raises KeyError with the known kinds."""
    _load_builtin()
    try:
        return _READERS[kind]
    except KeyError:
        raise KeyError(f"unknown kind {kind!r}; known kinds: {', '.join(sorted(_READERS))}") from None


def _load_builtin() -> None:
    # Importing the built-in table registers the readers; deferred so importing
    # the registry alone stays cheap and free of cycles.
    from cadkg.ingest import builtin  # noqa: F401
