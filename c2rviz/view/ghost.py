"""The ghost's other parts: the tool's path while a path is played, a refused target in red.

While a robot plays a path (``world.moves.Travel.path``: a ``movel`` line, a
planned path, any ``motion.path_play.PathPlay``), the page draws the tool
point's way along it as a line below the robot's root (``/robots/<name>/path``),
computed once per path with Pinocchio: through the path's joint rows (a
planned path's ``joint_path``, a line's ``qs``) spread to ``PATH_POINTS``
points along the joint-space path, or, for a path that exposes no rows, its own
samples from now to its arrival. The line goes when the arm comes to rest.

When a guarded command is refused because its target or its way collides, a red
copy of the arm stands at the refused target for ``REFUSED_S`` with a label
naming the pair that would touch (``/robots/<name>/refused``).

``ghost off`` (``RobotState.ghost``) hides the path line and the red copy, as it
hides the target ghost.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import pinocchio as pin
import viser

from .robot_view import RobotView

PATH_POINTS = 256
"""Points of a drawn path at most."""
PATH_RGB = (0.15, 0.45, 1.0)
REFUSED_RGBA = (1.0, 0.1, 0.05, 0.5)
REFUSED_S = 5.0
"""How long a refused target shows [s]."""


def tool_path(view: RobotView, path: Any, tool: pin.SE3, now: float) -> np.ndarray:
    """The tool point along ``path`` (a ``PathPlay``) in the robot's root frame [m], shape
    (k, 3), k <= ``PATH_POINTS``; ``now`` [s of the clock] starts a path without rows."""
    rows = getattr(path, "joint_path", None)
    if rows is None:
        rows = getattr(path, "qs", None)
    if rows is not None and len(rows) >= 2:
        rows = np.asarray(rows, dtype=float)
        steps = np.linalg.norm(np.diff(rows, axis=0), axis=1)
        along = np.concatenate([[0.0], np.cumsum(steps)])
        at = np.linspace(0.0, along[-1], min(PATH_POINTS, max(2, 8 * len(rows))))
        qs = np.column_stack([np.interp(at, along, rows[:, j]) for j in range(rows.shape[1])])
    else:
        times = np.linspace(now, max(float(path.arrival), now), PATH_POINTS // 2)
        qs = np.array([path.sample(float(t)) for t in times])
    robot = view.robot
    base = robot.base_placement
    return np.array([(base * robot.ee_pose(q) * tool).translation for q in qs])


class RobotGhost:
    """One robot's path line and refused copy; see the module docstring.

    Attributes:
        path_node: The path's line node (made at the first path), or None.
        refused_root: The red copy's root node (made at the first refusal), or None.
        label: The red copy's label, or None.
        refused_until: Real time [s] the red copy shows until (-inf: hidden).
        path_shown: The path object drawn, or None.
    """

    def __init__(self, server: viser.ViserServer, view: RobotView) -> None:
        self._scene = server.scene
        self.view = view
        self.path_node: Any = None
        self.path_shown: object | None = None
        self.refused_root: Any = None
        self._refused_frames: list[tuple[int, Any]] = []
        self.label: Any = None
        self.refused_until = -np.inf

    def show_path(self, path: object | None, tool: pin.SE3, now: float) -> None:
        """Draw ``path`` (a ``PathPlay``, computed once per path) or, for None, hide it."""
        if path is self.path_shown:
            return
        self.path_shown = path
        if path is None:
            if self.path_node is not None:
                self.path_node.visible = False
            return
        points = tool_path(self.view, path, tool, now).astype(np.float32)
        segments = np.stack([points[:-1], points[1:]], axis=1)
        if self.path_node is None:
            self.path_node = self._scene.add_line_segments(
                f"{self.view.prefix}/path", points=segments, colors=PATH_RGB, thickness=0.008
            )
        else:
            self.path_node.points = segments
            self.path_node.visible = True

    def refuse(
        self, q: Sequence[float], pair: tuple[str, str], tool: pin.SE3, now_s: float
    ) -> None:
        """Show the arm at the refused target ``q`` [rad or m] in red, naming ``pair``, until
        ``REFUSED_S`` after real time ``now_s`` [s]."""
        view = self.view
        if self.refused_root is None:
            self.refused_root, self._refused_frames = view.add_copy("refused", REFUSED_RGBA)
        q = tuple(q)
        view.pose_copy(self._refused_frames, q)
        robot = view.robot
        where = (robot.base_placement * robot.ee_pose(q) * tool).translation
        text = f"refused: {pair[0]} would hit {pair[1]}"
        if self.label is None:
            self.label = self._scene.add_label(
                f"{view.prefix}/refused/label", text, position=where, anchor="bottom-center"
            )
        else:
            self.label.text = text
            self.label.position = where
        self.refused_root.visible = True
        self.refused_until = now_s + REFUSED_S

    def expire(self, now_s: float, shown: bool = True) -> float:
        """Hide the red copy if its time is over (or ``shown`` is False); return how long it
        still shows [s] (inf: hidden)."""
        if self.refused_root is None or self.refused_until == -np.inf:
            return np.inf
        if shown and now_s < self.refused_until:
            return float(self.refused_until - now_s)
        self.refused_root.visible = False
        self.refused_until = -np.inf
        return np.inf
