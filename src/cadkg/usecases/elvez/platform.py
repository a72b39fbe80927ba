"""Frames of the ELVEZ cell and the points of interest of its elements.

The manifest places each platform in the cell (``cell → platform_rf``), the platform scene
places its elements (``platform_rf → ID0001platform → ID0002platform``), and an element's
definition places its keys, collision boxes, taping spots, trays and tool frames in the
element's frame. :class:`FrameTree` joins the first two; the functions below give the third in
the element's frame, as the reference node computes them.
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Mapping

from cadkg.errors import NotFound, QueryError
from cadkg.geometry.poses import IDENTITY, Pose
from cadkg.usecases.elvez.files.definitions import Key, PlacedBox

__all__ = ["FrameTree", "box_centre", "element_frame", "key_centre", "tape_spot_centre", "xyz_angles"]

# The reference's taping-spot formula uses 1.57 for a quarter turn; kept so answers match.
_QUARTER_TURN = 1.57


def element_frame(cad_id: str, platform: str) -> str:
    """The frame of a platform element, as the reference node names it: ``ID0002platform``."""
    return f"{cad_id}{platform}"


class FrameTree:
    """Frames with a parent and a pose in it; poses of any frame in any other of the same tree."""

    def __init__(self, parents: Mapping[str, tuple[str, Pose]]) -> None:
        self._parents = dict(parents)
        self._rooted: dict[str, tuple[str, Pose]] = {}
        self._names = set(self._parents) | {parent for parent, _ in self._parents.values()}

    def __contains__(self, name: object) -> bool:
        return name in self._names

    def rooted(self, name: str) -> tuple[str, Pose]:
        """The root of ``name``'s tree and the pose of ``name`` in it.

        Raises
        ------
        NotFound
            When no frame is called ``name``.
        QueryError
            When the frames above ``name`` form a cycle.
        """
        if name in self._rooted:
            return self._rooted[name]
        if name not in self:
            raise NotFound(f"no frame {name!r}")
        chain: list[str] = []
        node = name
        while node in self._parents and node not in self._rooted:
            if node in chain:
                raise QueryError(f"the frames above {name!r} form a cycle: {' → '.join([*chain, node])}")
            chain.append(node)
            node = self._parents[node][0]
        root, pose = self._rooted.get(node, (node, IDENTITY))
        for child in reversed(chain):
            pose = pose * self._parents[child][1]
            self._rooted[child] = (root, pose)
        return self._rooted.get(name, (name, IDENTITY))

    def pose(self, frame: str, reference: str) -> Pose:
        """The pose of ``frame`` expressed in ``reference``.

        Raises
        ------
        NotFound
            When either frame is unknown.
        QueryError
            When the two frames are not in one tree (nothing places one relative to the other).
        """
        root, pose = self.rooted(frame)
        reference_root, reference_pose = self.rooted(reference)
        if root != reference_root:
            raise QueryError(
                f"frame {frame!r} (under {root!r}) and frame {reference!r} (under {reference_root!r}) "
                "are not connected; place one tree in the other with a [[frame]] of the manifest"
            )
        return reference_pose.inverse() * pose

    def transforms(self) -> Iterator[tuple[str, str, Pose]]:
        """Every ``(parent, child, pose of child in parent)``, as /tf_static would publish them."""
        for child, (parent, pose) in self._parents.items():
            yield parent, child, pose


def key_centre(key: Key) -> Pose:
    """The centre of a guide's key (the middle of its gap) in the element's frame: the key's
    corner moved half its length, gap and height along its own axes."""
    return key.corner * Pose((key.length / 2, key.gap / 2, key.height / 2))


def box_centre(box: PlacedBox) -> Pose:
    """The centre of a tray's floor: its corner moved half its x and y sizes."""
    return box.corner * Pose((box.size[0] / 2, box.size[1] / 2, 0.0))


def xyz_angles(pose: Pose) -> tuple[float, float, float]:
    """The angles ``R, P, Y`` of a rotation ``Rx(R)·Ry(P)·Rz(Y)`` (the definitions' order)."""
    x, y, z, w = pose.orientation
    r00 = 1 - 2 * (y * y + z * z)
    r01 = 2 * (x * y - z * w)
    r02 = 2 * (x * z + y * w)
    r12 = 2 * (y * z - x * w)
    r22 = 1 - 2 * (x * x + y * y)
    return (math.atan2(-r12, r22), math.asin(max(-1.0, min(1.0, r02))), math.atan2(-r01, r00))


def tape_spot_centre(spot: PlacedBox, guide: Pose) -> Pose:
    """The centre of a taping spot in the element's frame, as the reference computes it: half
    the spot's length along its x, and along its y as far as the cable line through the centre
    of its guide's key (``guide``), at that centre's height.

    The distance is measured from the spot's corner towards the guide, with the angle of that
    line taken in the first quadrant and a quarter turn of 1.57; a guide straight above or
    below the corner (no x offset) gives a right angle where the reference divides by zero.
    """
    corner = spot.corner
    dx = guide.position[0] - corner.position[0]
    dy = guide.position[1] - corner.position[1]
    distance = math.hypot(dx, dy)
    angle = math.atan(abs(dy) / abs(dx)) if dx else math.pi / 2
    turn = _QUARTER_TURN - xyz_angles(corner)[2] - angle
    along = distance * math.cos(turn)
    return corner * Pose((spot.size[0] / 2, along, guide.position[2] - corner.position[2]))
