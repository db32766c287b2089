"""Each robot's workcell objects and collisions, and its trail, drawn in the page.

Objects hang below the robot's root node (``/robots/<name>/objects/<object>``)
at ``base_placement * placement`` (the root stands at the robot's origin, so
an object's world pose is ``origin * base_placement * placement``), translucent
in their own colour. A new object list replaces the old nodes. While a link
collides, a red translucent copy of its visual geometry shows over it, and an
object it hits turns red. The trail is one line-segment node per robot
(``/robots/<name>/trail``, below the root: ``TrailKeeper`` gives points in the
model's world frame, the root's), redrawn only when ``TrailKeeper.changed`` moved.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import pinocchio as pin
import viser

from ..collision.workcell import WorkcellObject
from ..observers.trail import TrailKeeper
from .robot_view import RobotView, node_name, wxyz

__all__ = ["COLLISION_RGBA", "TRAIL_RGB", "TrailLayer", "WorkcellLayer", "add_object"]

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
