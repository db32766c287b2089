"""The logical cameras, drawn in the page: each one's frustum as line segments.

A camera is a node at its world pose (``/cameras/<name>``) holding its frustum in its
own frame: four edges from the lens (the origin) to the far plane's corners at
``x = range`` and that plane's rectangle, in ``CAMERA_RGB``, and its name as a label
at the lens. A camera in blackout is drawn in ``DARK_RGB``. Cameras change seldom, so
every change redraws them all.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
import viser

from ..world.cameras import Camera
from .robot_view import node_name, wxyz

__all__ = ["CAMERA_RGB", "DARK_RGB", "CameraLayer", "frustum_segments"]

CAMERA_RGB = (0.95, 0.75, 0.1)
DARK_RGB = (0.3, 0.3, 0.3)


def frustum_segments(camera: Camera) -> np.ndarray:
    """The frustum's 8 edges in the camera's frame, shape (8, 2, 3) [m]."""
    far = camera.range_m
    half_w = far * math.tan(camera.h_fov_rad / 2.0)
    half_h = far * math.tan(camera.v_fov_rad / 2.0)
    corners = [(far, sy * half_w, sz * half_h) for sy, sz in ((1, 1), (-1, 1), (-1, -1), (1, -1))]
    lens = (0.0, 0.0, 0.0)
    edges = [(lens, c) for c in corners]
    edges += [(corners[i], corners[(i + 1) % 4]) for i in range(4)]
    return np.array(edges, dtype=np.float32)


class CameraLayer:
    """Every camera's frustum; see the module docstring.

    Attributes:
        nodes: Each camera's frustum node and label, by name.
    """

    def __init__(self, server: viser.ViserServer) -> None:
        self._scene = server.scene
        self.nodes: dict[str, tuple[Any, Any]] = {}

    def show(self, cameras: Sequence[Camera], now: float) -> None:
        """Draw ``cameras`` as they are at clock time ``now`` [s]."""
        for node, label in self.nodes.values():
            label.remove()  # first: removing the node takes its children with it
            node.remove()
        self.nodes.clear()
        for camera in cameras:
            path = f"/cameras/{node_name(camera.name)}"
            node = self._scene.add_line_segments(
                path,
                points=frustum_segments(camera),
                colors=DARK_RGB if camera.dark(now) else CAMERA_RGB,
                thickness=0.004,
                position=tuple(camera.pose.translation),
                wxyz=wxyz(camera.pose.rotation),
            )
            label = self._scene.add_label(f"{path}/label", camera.name, anchor="bottom-left")
            self.nodes[camera.name] = (node, label)
