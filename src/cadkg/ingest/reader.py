"""What a reader of one input format declares: its kind, suffixes, function and sniffer.

Readers are listed in :mod:`cadkg.ingest.formats` (the formats no single use case owns) and
in each use case's declaration; :mod:`cadkg.registry` keeps the one table of them.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path

__all__ = ["Reader", "Sniffer"]

Sniffer = Callable[[bytes], bool]


@dataclass(frozen=True)
class Reader:
    """A registered input format: ``read(path) -> records``."""

    kind: str
    suffixes: tuple[str, ...]
    read: Callable[[str | Path], Sequence[object]]
    description: str
    # Whether the first bytes of a file are of this format, for suffixes several formats share.
    sniff: Sniffer | None = None
    # Records one by one, for formats big enough that a build should map and load the
    # first rows while the last are still being converted.
    stream: Callable[[str | Path], Iterator[object]] | None = None
