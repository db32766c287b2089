"""The parts in a recording's bag (and on rosbridge's ``/tf``): one TF frame each.

Each part is the frame ``parts/NAME`` on ``/tf``, a child of the world's frame (the
cell's ``world``, or the robot's root link for a robot alone), written when the parts
change or move, at most once per frame of the world's clock; and a marker of its shape
and colour in that frame (namespace ``parts``, one id per name: ADD when it appears or
changes, DELETE when it goes) on the first robot's marker topic.
"""

from __future__ import annotations

from collections.abc import Sequence

import pinocchio as pin

from ..ros import messages as mk
from ..ros.messages import INT32, Msg, tf_message, transforms
from ..world.parts import Part

__all__ = ["PART_FRAME", "PartFrames", "part_items", "part_transforms"]

PART_FRAME = "parts/{name}"
"""A part's TF frame."""


def xyz_xyzw(placement: pin.SE3) -> tuple[Sequence[float], Sequence[float]]:
    """Translation and quaternion (x, y, z, w) of ``placement`` (as ``bag_topics``'s, which
    this module does not import: rosbridge uses it, and the start loads no rosbags)."""
    x, y, z, qx, qy, qz, qw = pin.SE3ToXYZQUAT(placement).tolist()
    return (x, y, z), (qx, qy, qz, qw)


def part_items(
    parent: str, to_parent: pin.SE3, parts: Sequence[Part]
) -> list[tuple[str, str, Sequence[float], Sequence[float]]]:
    """Each part's frame in ``parent`` (``to_parent`` takes a world pose into ``parent``),
    as ``messages.transforms`` takes them."""
    return [
        (parent, PART_FRAME.format(name=part.name), *xyz_xyzw(to_parent * part.pose))
        for part in parts
    ]


def part_transforms(t_s: float, parent: str, to_parent: pin.SE3, parts: Sequence[Part]) -> Msg:
    """A ``TFMessage`` placing each part's frame in ``parent`` (see ``part_items``)."""
    return tf_message(transforms(t_s, part_items(parent, to_parent, parts)))


class PartFrames:
    """What of the parts a bag holds: their marker ids and shapes, and when /tf was last
    written."""

    def __init__(self, frame_s: float) -> None:
        self.frame_s = frame_s
        self.ids: dict[str, int] = {}
        self.shapes: dict[str, tuple[object, ...]] = {}
        self.next_id = 0
        self.last_t: float | None = None
        self.pending: Sequence[Part] | None = None

    def markers(self, t_s: float, parts: Sequence[Part]) -> list[Msg]:
        """The marker changes since the last call (ADD new or changed, DELETE gone)."""
        now: dict[str, tuple[object, ...]] = {
            p.name: (p.obj.shape, p.obj.size, p.obj.rgba) for p in parts
        }
        out = [
            mk.delete_marker(t_s, PART_FRAME.format(name=name), "parts", self.ids.pop(name))
            for name in list(self.shapes)
            if name not in now
        ]
        for part in parts:
            if self.shapes.get(part.name) == now[part.name]:
                continue
            if part.name not in self.ids:
                self.ids[part.name] = self.next_id
                self.next_id = (self.next_id + 1) % INT32
            out.append(
                mk.object_marker(
                    t_s,
                    PART_FRAME.format(name=part.name),
                    "parts",
                    self.ids[part.name],
                    part.obj.shape,
                    part.obj.size,
                    (0.0, 0.0, 0.0),
                    (0.0, 0.0, 0.0, 1.0),
                    part.obj.rgba,
                )
            )
        self.shapes = now
        return out

    def due(self, t: float) -> bool:
        """Whether /tf may be written at clock time ``t`` [s] (once a frame)."""
        return self.last_t is None or t >= self.last_t + self.frame_s * 0.999
