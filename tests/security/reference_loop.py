"""A fixed piece of a reader's kind of work, timed to scale what the attacks take.

A process that shares its core with others takes two to three times the CPU seconds it takes
alone (caches and the sibling hyperthread are shared), and a CI machine is shared. So the
attack tests do not bound a reader's CPU seconds but its CPU time in units of this loop, timed
in the same process beside each read: a loaded machine slows both alike. The loop does what
readers do, in about the proportions they do it: text split into rows and fields, numbers
parsed, XML parsed and walked, a record made per row.
"""

from __future__ import annotations

import csv
import functools
import io
import time

from lxml import etree

__all__ = ["reference_seconds"]

_ROWS = 200
_CSV = "\n".join(f"W{i};X{i % 7}:{i % 13};X{i % 5}:{i % 11};{i * 0.25:.2f};grey" for i in range(_ROWS))
_WIRE = '<wire id="W{0}" from="X{1}" to="X{2}" length="{3:.2f}">grey</wire>'
_WIRES = "".join(_WIRE.format(i, i % 7, i % 5, i * 0.25) for i in range(_ROWS))
_XML = f"<wires>{_WIRES}</wires>".encode()
_FIELDS = ("id", "from", "to", "length", "colour")
_REPEATS = 4


def _once() -> int:
    records = []
    for row in csv.reader(io.StringIO(_CSV), delimiter=";"):
        records.append({**dict(zip(_FIELDS, row, strict=True)), "length": float(row[3])})
    for element in etree.fromstring(_XML):
        length = float(element.get("length", "0"))
        records.append({**element.attrib, "length": length, "colour": element.text})
    return len(records)


@functools.cache
def _warm() -> None:
    _once()  # the first run in a process pays for what a read's seed already paid


def reference_seconds() -> float:
    """CPU seconds this process takes for the loop now (about 10 ms on a quiet machine)."""
    _warm()
    started = time.process_time()
    for _ in range(_REPEATS):
        _once()
    return time.process_time() - started
