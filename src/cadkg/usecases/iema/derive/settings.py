"""The settings of the cabinet geometry: the manifest's ``[derive]`` table.

```toml
[derive]                         # optional; these are the defaults
approach_distance = 0.15         # metres in front of a component for its target pose
rail_pattern = "^RAIL"           # labels of DIN rails (a regular expression)
cluster_tolerance = 0.005        # metres: pins this close in height / column form a cluster
robot_zones = ["Q", "QE"]        # a wire with an end whose zone ('Zona') is not one of these is a person's
```
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass
from typing import Any

from cadkg.ingest.manifest import finite
from cadkg.usecase import Settings
from cadkg.usecases.iema.robot_scope import DEFAULT_ZONES

__all__ = ["DERIVE_SETTINGS", "DeriveSpec"]


@dataclass(frozen=True, slots=True)
class DeriveSpec:
    """Settings of the derived geometry (see cadkg.usecases.iema.derive.cabinet)."""

    approach_distance: float = 0.15
    rail_pattern: str = "^RAIL"
    cluster_tolerance: float = 0.005
    # The connection-list zones of the cabinet itself: the robot's wires (cadkg.usecases.iema.robot_scope).
    robot_zones: tuple[str, ...] = DEFAULT_ZONES


def _read(table: Mapping[str, Any], fail: Callable[..., Exception]) -> DeriveSpec:
    defaults = DeriveSpec()
    values: dict[str, Any] = {}
    for key in ("approach_distance", "cluster_tolerance"):
        value = table.get(key, getattr(defaults, key))
        if not finite(value) or value < 0:
            raise fail(key, f"{key!r} must be a non-negative number of metres", found=value)
        values[key] = float(value)
    pattern = table.get("rail_pattern", defaults.rail_pattern)
    try:
        if not isinstance(pattern, str):
            raise TypeError
        re.compile(pattern)
    except (re.error, TypeError):
        raise fail("rail_pattern", "not a regular expression", found=pattern, expected="e.g. ^RAIL") from None
    zones = table.get("robot_zones", list(defaults.robot_zones))
    if not isinstance(zones, list) or not all(isinstance(z, str) and z.strip() for z in zones):
        expected = 'e.g. ["Q", "QE"]'
        raise fail("robot_zones", "not a list of zone names", found=zones, expected=expected)
    return DeriveSpec(rail_pattern=pattern, robot_zones=tuple(z.strip() for z in zones), **values)


def _state(spec: DeriveSpec) -> Iterator[tuple[str, str | float]]:
    yield "approachDistance", spec.approach_distance
    yield "railPattern", spec.rail_pattern
    yield "clusterTolerance", spec.cluster_tolerance
    # Stated only when the manifest changes them: a cell without ck:robotZone has the default.
    if spec.robot_zones != DEFAULT_ZONES:
        for zone in spec.robot_zones:
            yield "robotZone", zone


DERIVE_SETTINGS = Settings(
    keys=frozenset({"approach_distance", "rail_pattern", "cluster_tolerance", "robot_zones"}),
    read=_read,
    state=_state,
)
