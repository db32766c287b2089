"""NAME.html: a recording as a self-contained page that plays in any browser, no server.

The frames of NAME.csv are replayed into a private, offline viser scene (the
page's own robot view, so it looks as the live page does) while viser's scene
serializer keeps every message and the pauses between them; ``as_html`` then
bundles the player (play/pause, a timeline) and the recording into one file.
Frames are thinned to at most ``HTML_HZ`` a second and ``MAX_HTML_FRAMES`` in
all, so a long run stays a page a browser opens (README: Record and replay).
"""

from __future__ import annotations

import csv
import logging
from pathlib import Path

import pinocchio as pin

from .recorder import Recorded
from .robot import Robot
from .view import adapter
from .view.robot_view import RobotView
from .visuals import load_link_geometry

__all__ = ["HTML_HZ", "MAX_HTML_FRAMES", "write_html"]

log = logging.getLogger("c2rviz.record")

HTML_HZ = 30.0
"""Most frames a second kept in NAME.html."""
MAX_HTML_FRAMES = 20_000
"""Most frames kept in NAME.html (11 minutes at ``HTML_HZ``); a longer run is thinned."""


def write_html(recorded: Recorded, robot: Robot, origin: pin.SE3) -> Path:
    """Write NAME.html next to NAME.csv; blocking (for a thread). Returns its path."""
    times, joints = _frames(recorded.csv, robot.n)
    server = adapter.start("127.0.0.1", 0)  # offline: nothing connects to it
    try:
        server.scene.add_grid("/grid", width=4.0, height=4.0, cell_size=0.25, section_size=1.0)
        view = RobotView(
            server, recorded.name, robot, origin, load_link_geometry(robot.source), "robot"
        )
        if joints:
            view.draw(joints[0])
        serializer = server.get_scene_serializer()
        for before, now, q in zip(times, times[1:], joints[1:]):
            serializer.insert_sleep(now - before)
            view.draw(q)
        html = serializer.as_html()
    finally:
        adapter.stop(server)
    path = recorded.csv.with_suffix(".html")
    path.write_text(html, encoding="utf-8")
    return path


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
