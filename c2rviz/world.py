"""The one shared state: where the chain is and which markers stand.

Every TCP session and the viewer's sliders act on one ``World``; it hands each
accepted change to the scene. Values are validated before they get here (by
the session); the world only stores them, all in SI units.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pinocchio as pin

from .robot import Robot
from .scene import MAX_MARKERS, Marker, NullScene, Scene

__all__ = ["World"]


class World:
    """Shared robot state. Used from the asyncio thread only."""

    def __init__(
        self, robot: Robot, scene: Scene | None = None, rng: np.random.Generator | None = None
    ) -> None:
        self.robot = robot
        self.scene: Scene = scene if scene is not None else NullScene()
        self.rng = rng if rng is not None else np.random.default_rng()
        self.home_q = tuple(min(max(0.0, j.lower), j.upper) for j in robot.joints)
        self.q: tuple[float, ...] = self.home_q
        self.markers: list[Marker] = []
        self.client_count = 0

    def set_q(self, q: Sequence[float]) -> None:
        """Put the chain at ``q`` [rad or m], already checked against the limits."""
        self.q = tuple(q)
        self.scene.show_joints(self.q)

    def home(self) -> None:
        """All chain joints to zero (or the nearest limit where zero is outside)."""
        self.set_q(self.home_q)

    def randomize(self) -> None:
        """Every chain joint to a random value within its limits."""
        self.set_q(self.robot.random(self.rng))

    def ee_pose(self) -> pin.SE3:
        """End-effector placement in the base frame."""
        return self.robot.ee_pose(self.q)

    def add_marker(
        self, pose_in_base: pin.SE3 | None, rgb: tuple[float, float, float], shape: str
    ) -> Marker:
        """Drop a marker at ``pose_in_base``, or at the end effector when None."""
        in_base = self.ee_pose() if pose_in_base is None else pose_in_base
        placement = self.robot.base_placement * in_base
        x, y, z, w = pin.Quaternion(placement.rotation).coeffs()
        px, py, pz = placement.translation
        marker = Marker(
            (float(px), float(py), float(pz)), (float(w), float(x), float(y), float(z)), rgb, shape
        )
        self.markers.append(marker)
        if len(self.markers) > MAX_MARKERS:
            del self.markers[0]
        self.scene.add_marker(marker)
        return marker

    def clear(self) -> None:
        """Home the robot and remove every marker."""
        self.markers.clear()
        self.scene.clear_markers()
        self.home()

    def set_client_count(self, count: int) -> None:
        self.client_count = count
        self.scene.set_client_count(count)

    def note_command(self, line: str) -> None:
        self.scene.note_command(line)
