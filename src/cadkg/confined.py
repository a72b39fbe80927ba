"""Paths that come from file content or a request, opened only inside their root.

A name such as an X3D ``DEF``, a ``ck:meshUri`` or a path sent to ``load_files`` is not trusted.
:func:`parts_of` takes it apart as text (no empty name, NUL, absolute path or ``..``), and
:func:`open_inside` opens it one component at a time from a descriptor of the root, refusing a
link at every step (``O_NOFOLLOW``), so what is opened is inside the root whatever the disk
holds and however it changes meanwhile: swapping a folder for a link between the check and
the open is no longer a window, since there is no separate check. The caller reads or writes
through the descriptor it gets, or through :func:`read_inside` / :func:`write_files`; a name
from a file becomes one component with :func:`file_name`.

Names travel as lists (one entry per file), never joined into one string and split again.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import stat
import tempfile
from collections.abc import Iterator, Sequence
from pathlib import Path, PurePosixPath

from cadkg.errors import CadkgError

__all__ = [
    "OutsideRootError",
    "copies_inside",
    "file_name",
    "open_inside",
    "parts_of",
    "read_inside",
    "relative_to_root",
    "write_files",
]

_DIRECTORY = os.O_RDONLY | os.O_DIRECTORY | os.O_NOFOLLOW | os.O_CLOEXEC
_READ = os.O_RDONLY | os.O_NOFOLLOW | os.O_CLOEXEC | os.O_NONBLOCK
_WRITE = os.O_WRONLY | os.O_CREAT | os.O_TRUNC | os.O_NOFOLLOW | os.O_CLOEXEC


class OutsideRootError(CadkgError):
    """A name that does not lead to a regular file inside its root (or cannot be made there)."""


# What cannot stand in one component of a path, and the escape character itself.
_ESCAPES = {"~": "~7E", "/": "~2F", "\\": "~5C", "\x00": "~00"}


def file_name(text: str) -> str:
    """``text`` (a name from a file: an X3D ``DEF``, a CAD ID) as one component of a path:
    ``/``, ``\\``, NUL and ``~`` escaped as ``~XX``, and ``.`` or ``..`` (or nothing) prefixed
    with ``~``. Two different names never give the same file name.

    >>> file_name("../../etc/path")
    '..~2F..~2Fetc~2Fpath'
    """
    escaped = "".join(_ESCAPES.get(c, c) for c in text)
    return "~" + escaped if escaped in ("", ".", "..") else escaped


def parts_of(name: str) -> tuple[str, ...]:
    """The components of a relative name, checked as text.

    Raises
    ------
    OutsideRootError
        For an empty name, a NUL byte, an absolute path, a backslash, or a ``..`` component.
    """
    if not name or "\x00" in name or "\\" in name or name.startswith("/"):
        raise OutsideRootError(f"{name!r} is not a relative path inside its root")
    parts = tuple(p for p in PurePosixPath(name).parts if p != ".")
    if not parts or ".." in parts:
        raise OutsideRootError(f"{name!r} is not a relative path inside its root")
    return parts


def relative_to_root(given: str, root: Path) -> str:
    """``given`` relative to ``root``: as it is when relative, else with the root's own path
    (as written, or with its links resolved) taken off.

    Raises
    ------
    OutsideRootError
        When an absolute ``given`` does not start with the root.
    """
    if not given.startswith("/"):
        return given
    for base in dict.fromkeys((str(root), os.path.realpath(root))):
        prefix = base.rstrip("/") + "/"
        if given.startswith(prefix):
            return given[len(prefix) :]
    raise OutsideRootError(f"{given!r} is not a relative path inside its root")


@contextlib.contextmanager
def _directory(root: Path, parts: tuple[str, ...], make: bool) -> Iterator[int]:
    """A descriptor of the folder ``parts`` inside ``root``, walked without following a link."""
    fd = os.open(root, os.O_RDONLY | os.O_DIRECTORY | os.O_CLOEXEC)
    try:
        for part in parts:
            try:
                inner = os.open(part, _DIRECTORY, dir_fd=fd)
            except FileNotFoundError:
                if not make:
                    raise
                with contextlib.suppress(FileExistsError):
                    os.mkdir(part, 0o755, dir_fd=fd)
                inner = os.open(part, _DIRECTORY, dir_fd=fd)
            os.close(fd)
            fd = inner
        yield fd
    finally:
        os.close(fd)


def open_inside(root: Path, name: str, *, write: bool = False) -> int:
    """A descriptor of the regular file ``name`` inside ``root``: for reading, or for writing
    (folders made, the file made or emptied). The caller closes it.

    Raises
    ------
    OutsideRootError
        When ``name`` is refused by :func:`parts_of`, a component is a link or missing, or the
        file is not a regular file; the same words whatever the disk holds.
    """
    parts = parts_of(name)
    refused = OutsideRootError(f"{name!r} is not a file inside its root")
    try:
        with _directory(root, parts[:-1], make=write) as folder:
            fd = os.open(parts[-1], _WRITE if write else _READ, 0o644, dir_fd=folder)
    except (OSError, ValueError):
        raise refused from None
    if not stat.S_ISREG(os.fstat(fd).st_mode):
        os.close(fd)
        raise refused
    return fd


def read_inside(root: Path, name: str) -> bytes:
    """The bytes of the file ``name`` inside ``root`` (see :func:`open_inside`)."""
    with os.fdopen(open_inside(root, name), "rb") as file:
        return file.read()


def write_files(root: Path, files: dict[str, bytes] | Iterator[tuple[str, bytes]]) -> None:
    """Write each ``(name, content)`` inside ``root`` as :func:`open_inside` opens for writing;
    a folder is walked once for all the files written into it.

    Raises
    ------
    OutsideRootError
        On the first name that does not lead inside the root (the files before it are written).
    """
    items = files.items() if isinstance(files, dict) else files
    root.mkdir(parents=True, exist_ok=True)
    folders: dict[tuple[str, ...], int] = {}
    try:
        for name, content in items:
            parts = parts_of(name)
            try:
                folder = folders.get(parts[:-1])
                if folder is None:
                    with _directory(root, parts[:-1], make=True) as opened:
                        folder = folders[parts[:-1]] = os.dup(opened)
                # A new file, never the old one emptied: a file may be a hard link another
                # generation of the store shares.
                with contextlib.suppress(FileNotFoundError):
                    os.unlink(parts[-1], dir_fd=folder)
                fd = os.open(parts[-1], _WRITE | os.O_EXCL, 0o644, dir_fd=folder)
            except OSError:
                raise OutsideRootError(f"{name!r} is not a file inside its root") from None
            with os.fdopen(fd, "wb") as file:
                file.write(content)
    finally:
        for fd in folders.values():
            os.close(fd)


@contextlib.contextmanager
def copies_inside(root: Path, names: Sequence[str]) -> Iterator[tuple[Path, list[Path]]]:
    """``(scratch, copies)``: a private copy of each file ``names`` gives inside ``root``
    (relative, or absolute under the root), opened by :func:`open_inside` and kept under its
    path relative to the root in the folder ``scratch``, removed afterwards. Whoever reads the
    copies reads what was inside the root when it was opened, whatever changes there since.

    Raises
    ------
    OutsideRootError
        Naming the first name that does not lead to a file inside the root.
    """
    scratch = Path(tempfile.mkdtemp(prefix="cadkg-load-"))
    try:
        copies = []
        for name in names:
            try:
                rel = relative_to_root(name, root)
                source = os.fdopen(open_inside(root, rel), "rb")
            except OutsideRootError:
                raise OutsideRootError(f"{name!r} is not a file inside its root") from None
            target = scratch.joinpath(*parts_of(rel))
            target.parent.mkdir(parents=True, exist_ok=True)
            with source, target.open("wb") as copy:
                shutil.copyfileobj(source, copy)
            copies.append(target)
        yield scratch, copies
    finally:
        shutil.rmtree(scratch, ignore_errors=True)
