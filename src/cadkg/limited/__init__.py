"""A limited child: untrusted work (reading an input file, evaluating a query) in a forked
process without the network, under memory, CPU-time and wall-time limits.

:func:`run_limited` and :func:`stream_limited` fork the child and wait for it
(:mod:`cadkg.limited.child`); :class:`Limits`, how a process puts them on itself and what is
said past one are in :mod:`cadkg.limited.limits`; leaving the network is
:mod:`cadkg.limited.network`. The query workers of :mod:`cadkg.query.workers` are long-lived
and manage their own processes, with the same limits and messages.

>>> from cadkg.limited import Limits, run_limited
>>> run_limited(sum, ([1, 2, 3],), Limits(memory=64, cpu=5, wall=10))  # doctest: +SKIP
6
"""

from __future__ import annotations

# What the other stages call; the limits' own workings (how a process puts them on itself,
# what is said past one) are taken from the submodules by the query workers that share them.
from cadkg.limited.child import read_limited, run_limited, stream_limited
from cadkg.limited.limits import DEFAULT_QUERY_MEMORY, Limits, exceeded
from cadkg.limited.network import leave_network_or_warn

__all__ = [
    "DEFAULT_QUERY_MEMORY",
    "Limits",
    "exceeded",
    "leave_network_or_warn",
    "read_limited",
    "run_limited",
    "stream_limited",
]
