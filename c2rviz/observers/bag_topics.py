"""What a recording's bag says besides joint states: its text topics, markers and objects.

Pure builders and a buffer, for ``bag_recorder``: ``TextLines`` gathers the lines of
one frame of ``/c2rviz/commands`` or ``/c2rviz/replies`` into one ``String``;
``marker_message`` and ``object_message`` make a c2rviz marker or workcell object a
``visualization_msgs/Marker`` as the page draws it; ``namespaces`` gives each robot of
a cell a ROS namespace.

The parts in a recording's bag (and on rosbridge's ``/tf``): one TF frame each
(``PartFrames``, ``part_transforms``). Each part is the frame ``parts/NAME`` on ``/tf``, a
child of the world's frame (the cell's ``world``, or the robot's root link for a robot
alone), written when the parts change or move, at most once per frame of the world's
clock; and a marker of its shape and colour in that frame (namespace ``parts``, one id per
name: ADD when it appears or changes, DELETE when it goes) on the first robot's marker
topic.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING

import pinocchio as pin

from ..ros import messages as mk
from ..ros.messages import INT32, Msg, tf_message, transforms
from ..world.clock import Clock, Timer
from ..world.parts import Part
from ..world.state import Marker

if TYPE_CHECKING:  # rosbags loads at the first bag: rosbridge and the start use this module
    from ..collision.workcell import WorkcellObject
    from ..ros.bag_writer import BagWriter


PART_FRAME = "parts/{name}"
"""A part's TF frame."""


def xyz_xyzw(placement: pin.SE3) -> tuple[Sequence[float], Sequence[float]]:
    """Translation and quaternion (x, y, z, w) of ``placement``."""
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


MARKER_SIZE_M = 0.03
"""A marker's size as the page draws it (``view.markers``) [m]."""
_S = MARKER_SIZE_M
_SCALES = {  # visualization_msgs scale of each marker shape, as the page draws it
    "sphere": (_S, _S, _S),
    "cube": (_S, _S, _S),
    "cylinder": (2 * _S / 3, 2 * _S / 3, _S),
    "arrow": (1.7 * _S, _S / 4, 2 * _S / 3),
}
_NOT_ROS = re.compile(r"[^A-Za-z0-9_]")


def namespaces(names: Sequence[str]) -> dict[str, str]:
    """A ROS namespace for each robot name, unique: characters other than letters, digits
    and ``_`` become ``_``, a leading digit or ``_`` gets ``r`` before it."""
    out: dict[str, str] = {}
    for name in names:
        ns = _NOT_ROS.sub("_", name)
        ns = ns if ns[:1].isalpha() else "r" + ns
        base, k = ns, 1
        while ns in out.values():
            k += 1
            ns = f"{base}_{k}"
        out[name] = ns
    return out


class TextLines:
    """The lines of a text topic within one frame, written as one ``String`` when the frame
    is over (a flood of commands costs a list append each, not a bag message each)."""

    def __init__(
        self,
        writer: BagWriter,
        topic: str,
        clock: Clock,
        t0: float,
        period_s: float,
        on_error: Callable[[Exception], None],
    ) -> None:
        self.writer = writer
        self.on_error = on_error
        self.topic = topic
        self.clock = clock
        self.t0 = t0
        self.period_s = period_s
        self.t_s = 0.0  # the first line's time [s from the start]
        self.lines: list[str] = []
        self.timer: Timer | None = None

    def add(self, text: str) -> None:
        if not self.lines:
            now = self.clock.now()
            self.t_s = max(0.0, now - self.t0)
            self.timer = self.clock.call_at(now + self.period_s, self.flush)
        self.lines.append(text)

    def flush(self) -> None:
        if self.timer is not None:
            self.timer.cancel()
            self.timer = None
        lines, self.lines = self.lines, []
        if lines:
            try:
                self.writer.text(self.topic, self.t_s, "\n".join(lines))
            except Exception as exc:  # never into the loop's timer: the bag stops instead
                self.on_error(exc)


def marker_message(t_s: float, frame: str, number: int, marker: Marker) -> Msg:
    w, x, y, z = marker.wxyz
    return mk.marker(
        t_s,
        frame,
        "markers",
        number,
        mk.SHAPES[marker.shape],
        marker.position,
        (x, y, z, w),
        _SCALES.get(marker.shape, (_S, _S, _S)),
        (*marker.rgb, 1.0),
    )


def object_message(t_s: float, frame: str, number: int, obj: WorkcellObject) -> Msg:
    translation, quat = xyz_xyzw(obj.placement)
    uri = obj.mesh_path.as_uri() if obj.mesh_path is not None else ""
    return mk.object_marker(
        t_s, frame, "workcell", number, obj.shape, obj.size, translation, quat, obj.rgba, uri
    )
