"""The cell drawn in the page, a layer each: each robot's workcell objects, collisions and
trail (``WorkcellLayer``, ``TrailLayer``), the parts and their goals (``PartsLayer``), and
the logical cameras (``CameraLayer``).

Objects hang below the robot's root node (``/robots/<name>/objects/<object>``)
at ``base_placement * placement`` (the root stands at the robot's origin, so
an object's world pose is ``origin * base_placement * placement``), translucent
in their own colour. A new object list replaces the old nodes. While a link
collides, a red translucent copy of its visual geometry shows over it, and an
object it hits turns red. The trail is one line-segment node per robot
(``/robots/<name>/trail``, below the root: ``TrailKeeper`` gives points in the
model's world frame, the root's), redrawn only when ``TrailKeeper.changed`` moved.

Each part is a node at its world pose (``/parts/<name>``), solid in its colour, with a
label over it: its name, and ``held`` while a gripper holds it (the held part is drawn
a little translucent, so the fingers show through). Each goal is a wireframe outline of
its part's shape at the goal's pose (``/goals/<key>``), or a small frame for a type goal
with no part of its type yet. A part whose shape or colour is new gets a new node; a
moved one is only moved.

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
import pinocchio as pin
import viser

from ..collision.workcell import WorkcellObject
from ..observers.trail import TrailKeeper
from ..world.cameras import Camera
from ..world.part_rules import Goal
from ..world.parts import Part
from .robot_view import RobotView, node_name, wxyz

COLLISION_RGBA = (1.0, 0.0, 0.0, 0.6)  # a colliding link's overlay, a hit object
TRAIL_RGB = (1.0, 0.6, 0.0)


class WorkcellLayer:
    """One robot's objects and red collision overlays; see the module docstring.

    Attributes:
        objects: Each object's node, by object name.
        colliding: The names (links and objects) in collision at the last ``show_collisions``.
    """

    def __init__(self, server: viser.ViserServer, view: RobotView) -> None:
        self._scene = server.scene
        self._view = view
        self.objects: dict[str, Any] = {}
        self._rgba: dict[str, tuple[float, float, float, float]] = {}
        self._overlays: dict[str, list[Any]] = {}  # link name -> red copies (made at first hit)
        self.colliding: set[str] = set()

    def show_objects(self, objects: Sequence[WorkcellObject]) -> None:
        """Replace the drawn objects by ``objects`` (placements in the robot's base frame)."""
        for handle in self.objects.values():
            handle.remove()
        self.objects.clear()
        self._rgba.clear()
        base = self._view.robot.base_placement
        for obj in objects:
            name = f"{self._view.prefix}/objects/{node_name(obj.name)}"
            self.objects[obj.name] = add_object(self._scene, name, obj, base * obj.placement)
            self._rgba[obj.name] = obj.rgba
        self._tint(self.colliding)

    def show_collisions(self, pairs: Sequence[tuple[str, str]]) -> None:
        """Red what is in ``pairs`` (link or object names), the rest back to its colour."""
        self._tint({name for pair in pairs for name in pair})

    def _tint(self, names: set[str]) -> None:
        links = self._view.link_frames
        for name in names | self.colliding:
            hit = name in names
            if name in self.objects:
                rgba = COLLISION_RGBA if hit else self._rgba[name]
                self.objects[name].color = tuple(int(round(255 * c)) for c in rgba[:3])
            elif name in links:
                if hit and name not in self._overlays:
                    self._overlays[name] = self._view.add_overlay(name, COLLISION_RGBA)
                for node in self._overlays.get(name, ()):
                    node.visible = hit
        self.colliding = names


def add_object(scene: Any, name: str, obj: WorkcellObject, placement: pin.SE3) -> Any:
    """A node for ``obj`` at ``placement`` (its parent's frame), translucent in its colour."""
    rgb, alpha = obj.rgba[:3], obj.rgba[3]
    common: dict[str, Any] = {
        "position": placement.translation,
        "wxyz": wxyz(placement.rotation),
        "opacity": None if alpha >= 1.0 else alpha,
        "cast_shadow": False,
    }
    if obj.shape == "box":
        return scene.add_box(name, color=rgb, dimensions=obj.size, **common)
    if obj.shape == "sphere":
        return scene.add_icosphere(name, radius=obj.size[0], color=rgb, **common)
    if obj.shape == "cylinder":
        radius, length = obj.size
        return scene.add_cylinder(name, radius=radius, height=length, color=rgb, **common)
    import trimesh  # imported when first needed (a robot of primitives never loads it)

    mesh = trimesh.load(obj.mesh_path, force="mesh")
    assert isinstance(mesh, trimesh.Trimesh)
    vertices = np.asarray(mesh.vertices) * np.asarray(obj.size)
    return scene.add_mesh_simple(name, vertices, mesh.faces, color=rgb, **common)


class TrailLayer:
    """Every robot's trail, one line-segment node each; see the module docstring.

    Attributes:
        nodes: Each drawn trail's node, by robot name.
        drawn: The ``TrailKeeper.changed`` value drawn last.
    """

    def __init__(self, server: viser.ViserServer, segments: dict[str, str]) -> None:
        self._scene = server.scene
        self._segments = segments
        self.nodes: dict[str, Any] = {}
        self.drawn = 0

    def draw(self, keeper: TrailKeeper) -> None:
        """Redraw the trails if ``keeper`` changed since the last draw."""
        if keeper.changed == self.drawn:
            return
        self.drawn = keeper.changed
        on = set(keeper.robots())
        for robot in [r for r in self.nodes if r not in on]:
            self.nodes.pop(robot).remove()
        for robot in on:
            segments = keeper.segments(robot).astype(np.float32)
            node = self.nodes.get(robot)
            if node is not None:
                node.points = segments
                continue
            self.nodes[robot] = self._scene.add_line_segments(
                f"/robots/{self._segments.get(robot, node_name(robot))}/trail",
                points=segments,
                colors=TRAIL_RGB,
                thickness=0.005,
            )


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
