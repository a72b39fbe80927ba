"""What a reader of one input format declares: its kind, suffixes, function and sniffer.

Readers are listed in :mod:`cadkg.ingest.formats` (the formats no single use case owns) and
in each use case's declaration; :mod:`cadkg.registry` keeps the one table of them. A reader's
functions may be given as ``"module:attribute"`` names, as rdflib's plugin table names its
parsers: the module is imported when the function is first used, so listing or choosing among
the kinds does not import every parser (a registry that imported every reader to list their
names would make every command pay for trimesh, pandas and networkx first). A use case names
its other functions the same way with :func:`lazy`.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Generic, TypeVar

from cadkg.errors import RegistryError

__all__ = ["LazyField", "Reader", "Sniffer", "lazy", "resolve"]

T = TypeVar("T")

Sniffer = Callable[[bytes], bool]
ReadFunction = Callable[[str | Path], Sequence[object]]
StreamFunction = Callable[[str | Path], Iterator[object]]


def resolve(spec: str) -> Any:
    """The object ``spec`` (``"package.module:attribute"``) names, importing its module.

    Raises
    ------
    RegistryError
        When the module or the attribute is not there.
    """
    module_name, sep, attribute = spec.partition(":")
    if not sep or not module_name or not attribute:
        raise RegistryError(f"{spec!r} is not a 'module:attribute' name")
    module = importlib.import_module(module_name)
    try:
        return getattr(module, attribute)
    except AttributeError:
        raise RegistryError(f"{spec!r}: module {module_name} has no {attribute!r}") from None


class _Lazy:
    """A callable standing for the function a spec names, until its first call resolves it."""

    __slots__ = ("_function", "spec")

    def __init__(self, spec: str) -> None:
        self.spec = spec
        self._function: Callable[..., Any] | None = None

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        if self._function is None:
            self._function = resolve(self.spec)
        return self._function(*args, **kwargs)

    def __repr__(self) -> str:
        return f"lazy({self.spec!r})"


def lazy(spec: str) -> Callable[..., Any]:
    """A function imported from ``spec`` (``"module:attribute"``) when it is first called."""
    return _Lazy(spec)


class LazyField(Generic[T]):
    """A dataclass field that may be given as ``"module:attribute"`` and reads as the object.

    The name is resolved on first access and the object kept, so ``reader.read is read_wri``
    holds as it did when the function itself was declared. ``declared(obj)`` says whether a
    value was given without importing it (a sniffer's presence decides the registry's order).
    """

    def __init__(self, *, optional: bool = False) -> None:
        self._optional = optional
        self._name = ""

    def __set_name__(self, owner: type, name: str) -> None:
        self._name = "_" + name

    def __get__(self, obj: object | None, owner: type) -> T:
        if obj is None:
            if self._optional:  # the dataclass's default
                return None  # type: ignore[return-value]
            raise AttributeError(self._name[1:])  # no default: the field is required
        value = obj.__dict__[self._name]
        if isinstance(value, str):
            value = resolve(value)
            obj.__dict__[self._name] = value
        found: T = value
        return found

    def __set__(self, obj: object, value: T | str) -> None:
        obj.__dict__[self._name] = value

    def declared(self, obj: object) -> bool:
        """Whether ``obj`` was given a value (a name or the object), without resolving it."""
        return obj.__dict__[self._name] is not None

    def spec(self, obj: object) -> str | None:
        """The ``"module:attribute"`` still unresolved, or None once it is an object."""
        value = obj.__dict__[self._name]
        return value if isinstance(value, str) else None


# Compared by identity: comparing by value would import every function to compare them.
@dataclass(frozen=True, eq=False)
class Reader:
    """A registered input format: ``read(path) -> records``."""

    kind: str
    suffixes: tuple[str, ...]
    # Required all the same: the field's __get__ gives a dataclass no default (mypy sees one).
    read: LazyField[ReadFunction] = LazyField()
    description: str  # type: ignore[misc]
    # Whether the first bytes of a file are of this format, for suffixes several formats share.
    sniff: LazyField[Sniffer | None] = LazyField(optional=True)
    # Records one by one, for formats big enough that a build should map and load the
    # first rows while the last are still being converted.
    stream: LazyField[StreamFunction | None] = LazyField(optional=True)

    def sniffs(self) -> bool:
        """Whether the reader declares a sniffer, without importing it."""
        return _SNIFF.declared(self)


_SNIFF: LazyField[Sniffer | None] = vars(Reader)["sniff"]
