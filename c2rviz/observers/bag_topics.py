"""What a recording's bag says besides joint states: its text topics, markers and objects.

Pure builders and a buffer, for ``bag_recorder``: ``TextLines`` gathers the lines of
one frame of ``/c2rviz/commands`` or ``/c2rviz/replies`` into one ``String``;
``marker_message`` and ``object_message`` make a c2rviz marker or workcell object a
``visualization_msgs/Marker`` as the page draws it; ``namespaces`` gives each robot of
a cell a ROS namespace.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING

import pinocchio as pin

from ..ros import messages as mk
from ..ros.bag_writer import BagWriter
from ..ros.messages import Msg
from ..world.clock import Clock, Timer
from ..world.state import Marker

if TYPE_CHECKING:
    from ..collision.workcell import WorkcellObject

__all__ = [
    "MARKER_SIZE_M",
    "TextLines",
    "marker_message",
    "namespaces",
    "object_message",
    "xyz_xyzw",
]

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


def xyz_xyzw(placement: pin.SE3) -> tuple[Sequence[float], Sequence[float]]:
    x, y, z, qx, qy, qz, qw = pin.SE3ToXYZQUAT(placement).tolist()
    return (x, y, z), (qx, qy, qz, qw)


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
