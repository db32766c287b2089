"""The logical cameras, drawn in the page: each one's frustum, and what it sees.

A camera is a node at its world pose (``/cameras/<name>``) holding its frustum in its
own frame: four edges from the lens (the origin) to the far plane's corners at
``x = range`` and that plane's rectangle, in ``CAMERA_RGB``, and a label at the lens:
its name and the parts it sees now (``top: p1, p2``; ``top: none``; ``top: dark`` in
blackout, when the frustum is drawn in ``DARK_RGB``). A camera whose pose, view or
blackout changed gets a new node; otherwise only its label changes.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
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


def _key(camera: Camera, dark: bool) -> tuple[object, ...]:
    pose = tuple(camera.pose.homogeneous.ravel().tolist())
    return (pose, camera.h_fov_rad, camera.v_fov_rad, camera.range_m, dark)


class CameraLayer:
    """Every camera's frustum and label; see the module docstring.

    Attributes:
        nodes: Each camera's frustum node, label and what drew it, by name.
    """

    def __init__(self, server: viser.ViserServer) -> None:
        self._scene = server.scene
        self.nodes: dict[str, tuple[Any, Any, tuple[object, ...]]] = {}

    def show(
        self, cameras: Sequence[Camera], now: float, seen: Mapping[str, Sequence[str]]
    ) -> None:
        """Draw ``cameras`` as they are at clock time ``now`` [s], each seeing the parts
        named in ``seen``."""
        names = {camera.name for camera in cameras}
        for name in [n for n in self.nodes if n not in names]:
            self._remove(name)
        for camera in cameras:
            dark = camera.dark(now)
            key = _key(camera, dark)
            drawn = self.nodes.get(camera.name)
            if drawn is None or drawn[2] != key:
                if drawn is not None:
                    self._remove(camera.name)
                path = f"/cameras/{node_name(camera.name)}"
                node = self._scene.add_line_segments(
                    path,
                    points=frustum_segments(camera),
                    colors=DARK_RGB if dark else CAMERA_RGB,
                    thickness=0.004,
                    position=tuple(camera.pose.translation),
                    wxyz=wxyz(camera.pose.rotation),
                )
                label = self._scene.add_label(f"{path}/label", camera.name, anchor="bottom-left")
                drawn = self.nodes[camera.name] = (node, label, key)
            what = "dark" if dark else ", ".join(seen.get(camera.name, ())) or "none"
            text = f"{camera.name}: {what}"
            if drawn[1].text != text:
                drawn[1].text = text

    def _remove(self, name: str) -> None:
        node, label, _ = self.nodes.pop(name)
        label.remove()  # first: removing the node takes its children with it
        node.remove()
