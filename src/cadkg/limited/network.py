"""A limited child without the network.

pyoxigraph fetches what a query's ``SERVICE`` or an update's ``LOAD`` names. Recognising such
queries (:mod:`cadkg.outbound`) is the first, friendly refusal; what makes the promise hold
whatever the text is where it runs: the process (or thread) that evaluates enters a network
namespace of its own (``unshare(CLONE_NEWNET)``, with ``CLONE_NEWUSER`` when not root), where no
interface is up, loopback included: a connection fails before any packet leaves, whatever the
query says. Sockets opened before stay usable (a listening endpoint keeps its port), and a
namespace is per thread, so one thread of a server can leave the network while the others
answer. Where the kernel allows neither, :func:`leave_network` says why, and cadkg warns once
and relies on the recogniser alone.
"""

from __future__ import annotations

import ctypes
import os
import sys
import threading
from pathlib import Path

__all__ = ["leave_network", "leave_network_or_warn", "warn_unconfined"]

_CLONE_NEWNET = 0x40000000
_CLONE_NEWUSER = 0x10000000
_warned = threading.Event()


def leave_network() -> str | None:
    """Move the calling thread, and every thread and process it starts, into a network namespace
    of its own with no interface up. Returns ``None`` when done, else why it could not be.

    As root ``CLONE_NEWNET`` alone; otherwise inside a user namespace of its own (which maps the
    caller's user and group to themselves, so files are read and written as before), which the
    kernel allows only in a process of one thread.
    """
    unshare = getattr(ctypes.CDLL(None, use_errno=True), "unshare", None)
    if unshare is None:
        return "this system has no network namespaces (unshare)"
    if unshare(_CLONE_NEWNET) == 0:
        return None
    first = ctypes.get_errno()
    uid, gid = os.geteuid(), os.getegid()
    if unshare(_CLONE_NEWUSER | _CLONE_NEWNET) != 0:
        second = ctypes.get_errno()
        return f"unshare: {os.strerror(first)}; in a user namespace: {os.strerror(second)}"
    try:
        _map_ids(uid, gid)
    except OSError as err:
        return f"cannot map the user into its namespace: {err}"
    return None


def leave_network_or_warn() -> None:
    """:func:`leave_network`, or the one-time warning of why it could not (a thread initializer)."""
    why = leave_network()
    if why is not None:
        warn_unconfined(why)


def _map_ids(uid: int, gid: int) -> None:
    # Without a mapping the kernel refuses to create files (EOVERFLOW): the user stays itself.
    own = Path("/proc/thread-self")
    (own / "setgroups").write_text("deny")
    (own / "uid_map").write_text(f"{uid} {uid} 1")
    (own / "gid_map").write_text(f"{gid} {gid} 1")


def warn_unconfined(why: str) -> None:
    """Say once per process that queries run with the network reachable, and why."""
    if _warned.is_set():
        return
    _warned.set()
    print(
        f"cadkg: warning: queries cannot be kept from the network here ({why}); "
        "SERVICE and LOAD are refused by recognising them only (docs/server.md, Security)",
        file=sys.stderr,
        flush=True,
    )
