"""The parts and their goals, drawn in the page.

Each part is a node at its world pose (``/parts/<name>``), solid in its colour, with a
label over it: its name, and ``held`` while a gripper holds it (the held part is drawn
a little translucent, so the fingers show through). Each goal is a wireframe outline of
its part's shape at the goal's pose (``/goals/<key>``), or a small frame for a type goal
with no part of its type yet. A part whose shape or colour is new gets a new node; a
moved one is only moved.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import pinocchio as pin
import viser

from ..world.part_rules import Goal
from ..world.parts import Part
from .robot_view import node_name, wxyz

__all__ = ["GOAL_RGB", "HELD_OPACITY", "PartsLayer"]

GOAL_RGB = (0.1, 0.8, 0.3)
HELD_OPACITY = 0.7


def _shape_node(
    scene: Any,
    name: str,
    shape: str,
    size: Sequence[float],
    rgb: Sequence[float],
    wireframe: bool = False,
) -> Any:
    common: dict[str, Any] = {"color": tuple(rgb), "wireframe": wireframe, "cast_shadow": False}
    if shape == "box":
        return scene.add_box(name, dimensions=tuple(size), **common)
    if shape == "cylinder":
        return scene.add_cylinder(name, radius=size[0], height=size[1], **common)
    return scene.add_icosphere(name, radius=size[0], **common)


class PartsLayer:
    """Every part and goal of the world; see the module docstring.

    Attributes:
        nodes: Each part's node and label, by part name.
        goals: Each goal's node, by goal key.
    """

    def __init__(self, server: viser.ViserServer) -> None:
        self._scene = server.scene
        self.nodes: dict[str, tuple[Any, Any, tuple[object, ...]]] = {}
        self.goals: dict[str, Any] = {}

    def show_parts(self, parts: Sequence[Part]) -> None:
        """Draw ``parts`` as they are now (poses in the world frame)."""
        seen = set()
        for part in parts:
            seen.add(part.name)
            key = (part.obj.shape, part.obj.size, part.obj.rgba)
            drawn = self.nodes.get(part.name)
            if drawn is None or drawn[2] != key:
                if drawn is not None:
                    drawn[1].remove()  # first: removing the node takes its label with it
                    drawn[0].remove()
                path = f"/parts/{node_name(part.name)}"
                node = _shape_node(
                    self._scene, path, part.obj.shape, part.obj.size, part.obj.rgba[:3]
                )
                label = self._scene.add_label(f"{path}/label", part.name, anchor="bottom-left")
                drawn = self.nodes[part.name] = (node, label, key)
            node, label, _ = drawn
            node.position = part.pose.translation
            node.wxyz = wxyz(part.pose.rotation)
            held = part.holder is not None
            node.opacity = HELD_OPACITY if held else None
            label.text = f"{part.name} (held by {part.holder})" if held else part.name
        for name in [n for n in self.nodes if n not in seen]:
            node, label, _ = self.nodes.pop(name)
            label.remove()  # first: removing the node takes its label with it
            node.remove()

    def show_goals(self, goals: Sequence[Goal], parts: Sequence[Part]) -> None:
        """Replace the drawn goals by ``goals`` (outlines of their parts' shapes)."""
        for node in self.goals.values():
            node.remove()
        self.goals.clear()
        by_name = {part.name: part for part in parts}
        for goal in goals:
            kind = goal.kind
            part = (
                by_name.get(goal.key)
                if kind is None
                else next((p for p in parts if p.kind == kind), None)
            )
            path = f"/goals/{node_name(goal.key)}"
            if part is None:
                node = self._scene.add_frame(path, axes_length=0.05, axes_radius=0.003)
            else:
                node = _shape_node(
                    self._scene, path, part.obj.shape, part.obj.size, GOAL_RGB, wireframe=True
                )
            _place(node, goal.pose)
            self.goals[goal.key] = node


def _place(node: Any, pose: pin.SE3) -> None:
    node.position = pose.translation
    node.wxyz = wxyz(pose.rotation)
