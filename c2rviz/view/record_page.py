"""NAME.html: a recording as a self-contained page that plays in any browser, no server.

The frames of NAME.csv are replayed into a private, offline viser scene (the
page's own robot view and marker layer, so it looks as the live page does)
while viser's scene serializer keeps every message and the pauses between
them; the markers come from NAME.txt (its ``mark``, ``color``, ``marker`` and
``clear`` lines, timed by its ``sleep`` lines) and appear at the first frame
at or after their time. ``as_html`` then bundles the player (play/pause, a
timeline) and the recording into one file.
Frames are thinned to at most ``HTML_HZ`` a second and ``MAX_HTML_FRAMES`` in
all, so a long run stays a page a browser opens (README: Record and replay).
"""

from __future__ import annotations

import csv
import logging
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pinocchio as pin

from ..observers.recorder import Recorded
from ..protocol.grammar import parse_line
from ..protocol.verbs.connection import Sleep
from ..protocol.verbs.markers import Clear, Color, Mark, MarkerShape
from ..robot.model import Robot
from ..robot.visuals import load_link_geometry
from ..world.effects import Marker
from ..world.state import RobotState
from . import adapter
from .markers import MarkerLayer
from .robot_view import RobotView

__all__ = ["HTML_HZ", "MAX_HTML_FRAMES", "write_html"]

log = logging.getLogger("c2rviz.record")

HTML_HZ = 30.0
"""Most frames a second kept in NAME.html."""
MAX_HTML_FRAMES = 20_000
"""Most frames kept in NAME.html (11 minutes at ``HTML_HZ``); a longer run is thinned."""


def write_html(recorded: Recorded, state: RobotState) -> Path:
    """Write NAME.html next to NAME.csv for the recording of ``state``'s robot; blocking
    (for a thread). Returns its path (an ``observers.recordings.Exporter``)."""
    robot, origin = state.robot, state.origin
    times, joints = _frames(recorded.csv, robot.n)
    server = adapter.start("127.0.0.1", 0)  # offline: nothing connects to it
    try:
        server.scene.add_grid("/grid", width=4.0, height=4.0, cell_size=0.25, section_size=1.0)
        view = RobotView(
            server, recorded.name, robot, origin, load_link_geometry(robot.source), "robot"
        )
        markers = MarkerLayer(server, {recorded.name: "robot"})
        events = _marker_events(recorded.txt, robot, origin)
        event = next(events, None)
        serializer = server.get_scene_serializer()
        for k, (now, q) in enumerate(zip(times, joints)):
            if k:
                serializer.insert_sleep(now - times[k - 1])
            while event is not None and event[0] <= now:
                if event[1] is None:
                    markers.clear(recorded.name)
                else:
                    markers.add(recorded.name, event[1])
                event = next(events, None)
            view.draw(q)
            markers.draw()
        html = serializer.as_html()
    finally:
        adapter.stop(server)
    path = recorded.csv.with_suffix(".html")
    path.write_text(html, encoding="utf-8")
    return path


def _marker_events(
    txt: Path | None, robot: Robot, origin: pin.SE3
) -> Iterator[tuple[float, Marker | None]]:
    """NAME.txt's markers in order, each with its time [s] from the start (None: a clear)."""
    if txt is None:  # a write error stopped the recording: no command file
        return
    t, rgb, shape = 0.0, (1.0, 0.0, 0.0), "sphere"  # a replaying session's style
    base = origin * robot.base_placement
    with open(txt, encoding="ascii") as file:
        for line in file:
            command = parse_line(line)  # written by the recorder: radians, base frame
            if isinstance(command, Sleep):
                t += command.seconds
            elif isinstance(command, Color):
                rgb = command.rgb
            elif isinstance(command, MarkerShape):
                shape = command.shape
            elif isinstance(command, Clear):
                yield t, None
            elif isinstance(command, Mark) and command.pose is not None:
                x, y, z, roll, pitch, yaw = command.pose
                pose = pin.SE3(pin.rpy.rpyToMatrix(roll, pitch, yaw), np.array([x, y, z]))
                placement = pose if command.in_world else base * pose
                qx, qy, qz, qw = map(float, pin.Quaternion(placement.rotation).coeffs())
                px, py, pz = map(float, placement.translation)
                yield t, Marker((px, py, pz), (qw, qx, qy, qz), rgb, shape)


def _frames(path: Path, n: int) -> tuple[list[float], list[tuple[float, ...]]]:
    """The CSV's times and joint values, at most ``HTML_HZ`` a second and
    ``MAX_HTML_FRAMES`` in all (the first and last frames always kept)."""
    with open(path, newline="") as file:
        rows = [[float(v) for v in row[: 1 + n]] for row in list(csv.reader(file))[1:]]
    if not rows:
        return [], []
    span = rows[-1][0] - rows[0][0]
    step = max(1.0 / HTML_HZ, span / MAX_HTML_FRAMES)
    kept = [rows[0]]
    for row in rows[1:-1]:
        if row[0] - kept[-1][0] >= step:
            kept.append(row)
    if len(rows) > 1:
        kept.append(rows[-1])
    return [row[0] for row in kept], [tuple(row[1:]) for row in kept]
