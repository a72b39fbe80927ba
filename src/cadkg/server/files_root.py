"""What ``load_files`` reads over HTTP: only files inside ``--files-root``, each copied from
inside it (:func:`cadkg.confined.copies_inside`) before a reader sees it."""

from __future__ import annotations

import contextlib
from collections.abc import Iterator, Sequence
from pathlib import Path

from cadkg.confined import OutsideRootError, copies_inside
from cadkg.server.context import ProtocolError

__all__ = ["confine", "files_root"]


def files_root(root: Path | None) -> Path:
    """The files root of the endpoint.

    Raises
    ------
    ProtocolError
        403 when the endpoint was started without one.
    """
    if root is None:
        raise ProtocolError(
            403, "load_files over HTTP reads files only under a directory named at start: --files-root DIR"
        )
    return root


@contextlib.contextmanager
def confine(paths: Sequence[str], root: Path | None) -> Iterator[tuple[Path, list[Path]]]:
    """Private copies of ``paths`` (each relative to ``root``, or absolute inside it), each
    opened inside the root by :func:`cadkg.confined.copies_inside`; the folder holding them.

    Raises
    ------
    ProtocolError
        403 without a root, or for a path outside it: the same words whether or not it exists,
        so the answers tell nothing about the rest of the disk.
    """
    base = files_root(root)
    names = list(paths)
    try:
        with copies_inside(base, names) as copied:
            yield copied
    except OutsideRootError as err:
        refused = next((n for n in names if repr(n) in str(err)), "")
        raise ProtocolError(403, f"{refused!r} is not under the files root of this endpoint") from None
