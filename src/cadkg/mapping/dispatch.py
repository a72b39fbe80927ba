"""The table of mappings, one per record type: records → triples of a :class:`TripleWriter`.

A module that maps records registers one function per record type with
``@map_record.register``; importing it is the registration. Core formats' mappings are in
this package, each use case's in its own ``mapping`` module.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import singledispatch

from cadkg.mapping.writer import TripleWriter

__all__ = ["map_record", "mapper"]


def mapper(record_type: type) -> Callable[[object, TripleWriter, str], None]:
    """The mapping of one record type (what :func:`map_record` dispatches to), looked up once."""
    found = _MAPPERS.get(record_type)
    if found is None:
        found = map_record.dispatch(record_type)
        if found is not map_record.dispatch(object):  # a mapping registered later still counts
            _MAPPERS[record_type] = found
    return found


_MAPPERS: dict[type, Callable[[object, TripleWriter, str], None]] = {}


@singledispatch
def map_record(record: object, w: TripleWriter, source_slug: str) -> None:
    raise TypeError(f"no mapping for records of type {type(record).__name__}")
