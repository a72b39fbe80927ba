"""EPLAN device tags and pin references, shared by every EPLAN export reader.

A device tag may carry the structure identifiers EPLAN puts in front of it:
``=FUNCTION+LOCATION-DEVICE`` (``=-F1500.1`` when both are empty). The graph keys
components by the bare device part (``F1500.1``), which is what the WRI table, the
CAD scene and the connection list have in common.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

__all__ = ["PinRef", "PinSyntaxError", "duct_labels", "normalize_label", "parse_pin_ref"]

_TAG = re.compile(r"^(?:=[^+\-=]*)?(?:\+[^\-=]*)?-?(?P<device>[^=+\-].*)?$")
_PART = re.compile(r"^[^\s:;]+$")


class PinSyntaxError(ValueError):
    """A pin reference does not follow ``DEVICE:PIN[:LEVEL]``."""


def normalize_label(raw: str) -> str:
    """``'=-F1500.1'`` → ``'F1500.1'``; ``'=A1+ST1-K3'`` → ``'K3'``; plain tags unchanged."""
    text = raw.strip()
    match = _TAG.match(text)
    if match is None:
        return text
    return (match.group("device") or "").strip()


_DUCT_SEPARATORS = re.compile(r"[;']")


def duct_labels(path: str) -> tuple[str, ...]:
    """The ducts a written duct path names: ``;`` in EPLAN's lists, ``'`` in the Komax ones."""
    return tuple(normalize_label(d) for d in _DUCT_SEPARATORS.split(path) if d.strip())


@dataclass(frozen=True, slots=True)
class PinRef:
    """A connection point: a device's pin, or a terminal's connection level.

    ``-F1500.1:14`` is pin ``14`` of device ``F1500.1``; ``-X1600:2:a`` is level ``a``
    of terminal ``2`` of terminal block ``X1600``.
    """

    component: str
    pin: str
    level: str | None
    raw: str

    @property
    def key(self) -> str:
        """``F1500.1:14`` or ``X1600:2:a``: the reference without structure prefixes."""
        tail = f":{self.level}" if self.level is not None else ""
        return f"{self.component}:{self.pin}{tail}"


# The common case in one match: ``=-``, ``-`` or nothing before a device tag that holds
# no ``=`` or ``+``, then pin and level without white space (``=-F1500.1:14``,
# ``-X1600:2:a``). Whatever it does not take goes through the checks below, which give
# the same parts for everything it takes and say what is wrong otherwise.
_PLAIN_REF = re.compile(r"(?:=?-)?([^=+\-:;\s][^=+:;\s]*):([^:;\s]+)(?::([^:;\s]+))?")


def parse_pin_ref(raw: str) -> PinRef:
    """Parse an EPLAN pin reference; raises :class:`PinSyntaxError` when malformed."""
    text = raw.strip()
    plain = _PLAIN_REF.fullmatch(text)
    if plain is not None:
        component, pin, level = plain.groups()
        return PinRef(component=component, pin=pin, level=level, raw=text)
    device_part, sep, rest = text.partition(":")
    if not sep:
        raise PinSyntaxError("no ':' between device and pin")
    component = normalize_label(device_part)
    parts = rest.split(":")
    if len(parts) > 2:
        raise PinSyntaxError("more than DEVICE:PIN:LEVEL")
    if not component or component.startswith(("-", "=", "+")):
        raise PinSyntaxError("no device tag before ':'")
    for part in (component, *parts):
        if not _PART.match(part):
            raise PinSyntaxError("empty part or white space inside the reference")
    level = parts[1] if len(parts) == 2 else None
    return PinRef(component=component, pin=parts[0], level=level, raw=text)
