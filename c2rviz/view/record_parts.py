"""The parts in a recorded page (NAME.html): a node each, which the player poses per frame.

Each part NAME.csv has poses for (``Frames.parts``) gets a node at ``/parts/robot/NAME``
in the world frame, its shape, size and colour from the first NAME.txt line that added it
(``Commands.parts``), with its name as a label over it, as the live page draws parts
(``parts_layer``). It is placed at its first frame's pose (hidden while it is not there);
the player (``record_player.js``) moves it to each frame's pose. A part with poses but no
``part`` line is left out, and said.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pinocchio as pin

from .record_commands import Commands
from .record_rows import POSE_COLUMNS, Frames
from .robot_view import node_name, wxyz

__all__ = ["add_parts", "placement_list"]

_SEGMENT = "robot"


def placement_list(placement: pin.SE3) -> list[float]:
    """``placement`` as x, y, z, qw, qx, qy, qz (the player's form)."""
    return [*map(float, placement.translation), *map(float, wxyz(placement.rotation))]


def add_parts(
    scene: Any, name: str, frames: Frames, commands: Commands, n: int, base: pin.SE3
) -> tuple[list[dict[str, Any]], list[str]]:
    """Add a node per part of ``frames`` (``n`` joints; ``base``: the base frame in the
    world) to ``scene``; return the player's description of each and the problems."""
    parts, problems = [], []
    for k, part in enumerate(frames.parts):
        column = n + len(POSE_COLUMNS) * (k + 1)
        shape = commands.parts.get(part)
        if shape is None:
            problems.append(f"{name}.txt never adds part {part!r}: it is not drawn")
            parts.append({"name": part, "column": column, "node": None})
            continue
        node = f"/parts/{_SEGMENT}/{node_name(part)}"
        common: dict[str, Any] = {"color": shape.rgb, "cast_shadow": False}
        if shape.shape == "box":
            handle = scene.add_box(node, dimensions=shape.size, **common)
        elif shape.shape == "cylinder":
            handle = scene.add_cylinder(node, radius=shape.size[0], height=shape.size[1], **common)
        else:
            handle = scene.add_icosphere(node, radius=shape.size[0], **common)
        scene.add_label(f"{node}/label", part, anchor="bottom-left")
        pose = frames.values[0, column : column + 6] if len(frames.times) else None
        if pose is not None and np.isfinite(pose).all():
            x, y, z, roll, pitch, yaw = map(float, pose)
            at = base * pin.SE3(pin.rpy.rpyToMatrix(roll, pitch, yaw), np.array([x, y, z]))
            handle.position = at.translation
            handle.wxyz = wxyz(at.rotation)
        else:
            handle.visible = False
        parts.append({"name": part, "column": column, "node": node})
    return parts, problems
