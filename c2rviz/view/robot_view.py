"""One robot drawn in the page: a root node at its place in the world, a frame per link.

Like viser's ``ViserUrdf``, a ``RobotView`` is one object per robot, under a
root node of its own (``/robots/<name>``) placed at the robot's origin in the
world frame, so a cell of several robots, the same model twice included,
draws in one scene. Below the root, the link frames nest as the URDF's tree
(``/robots/<name>/links/base_link/link_s/...``, ``link_tree``), each posed in its
parent link's frame by Pinocchio forward kinematics on the view's own ``Data``
(Pinocchio is the one source of kinematic truth): a link's pose in the world is
``origin * oMf``, the product of the poses down its path. A joint's turn is then
one orientation for the page. Each link's URDF geometry hangs below its frame at
its URDF origin.

While the robot travels, a translucent copy of the arm (the target ghost,
``/robots/<name>/target``) stands where the move ends; ``add_copy`` makes such
copies (``view.ghost`` adds the refused target's, in red).
"""

from __future__ import annotations

import dataclasses
import re
from typing import Any

import numpy as np
import pinocchio as pin
import viser

from ..robot.mesh_files import Mesh
from ..robot.model import Robot
from ..robot.visuals import DEFAULT_RGBA, LinkGeometry, Shape
from . import adapter
from .link_tree import LinkTree

GHOST_OPACITY = 0.3
GHOST_GREY = (0.7, 0.7, 0.72)  # for a mesh that brings colours of its own
_WXYZ_ORDER = [0, 1, 2, 6, 3, 4, 5]  # pin.SE3ToXYZQUAT's x y z qx qy qz qw as x y z w x y z


def wxyz(rotation: np.ndarray) -> np.ndarray:
    """A rotation matrix as a unit quaternion (w, x, y, z)."""
    x, y, z, w = pin.Quaternion(rotation).coeffs()
    return np.array([w, x, y, z])


def node_name(text: str) -> str:
    """``text`` as one segment of a viser node name."""
    return re.sub(r"[^A-Za-z0-9_.-]", "_", text) or "_"


class RobotView:
    """One robot's nodes in the scene; see the module docstring.

    Attributes:
        name: The robot's name in the world.
        robot: Its model and chain.
        root: The root node, at the robot's origin in the world frame.
        link_frames: Each link's frame node (Pinocchio body frame), by link name,
            posed in its parent link's frame (``link_pose``: in the root's).
        link_nodes: Each link's node name, by link name.
        target_frames: The ghost's link frames, by link name.
        collision_nodes: The collision geometry (hidden until asked for).
        sent_q: The chain values [rad or m] drawn last.
        sent_ee: The end effector's placement in the base frame drawn last.
        sent_target: The target [rad or m] the ghost shows (None: hidden).
    """

    def __init__(
        self,
        server: viser.ViserServer,
        name: str,
        robot: Robot,
        origin: pin.SE3,
        geometry: dict[str, LinkGeometry],
        segment: str,
    ) -> None:
        """Add the robot's nodes under ``/robots/<segment>``.

        Args:
            server: The viser server.
            name: The robot's name in the world.
            robot: Its model and chain.
            origin: Where its model's root stands in the world frame.
            geometry: Its links' shapes (``visuals.load_link_geometry``).
            segment: Its node name segment (unique in the scene).
        """
        self.name = name
        self.robot = robot
        self.origin = origin
        self._data = robot.model.createData()  # the world's robot.data is not ours
        self._probe = robot.model.createData()  # FK of poses not drawn (keeps _data's)
        self._scene = server.scene
        self.prefix = f"/robots/{segment}"
        self.root = self._scene.add_frame(
            self.prefix, show_axes=False, position=origin.translation, wxyz=wxyz(origin.rotation)
        )
        base = robot.base_placement
        self._scene.add_frame(
            f"{self.prefix}/base",
            axes_length=0.25,
            axes_radius=0.008,
            position=base.translation,
            wxyz=wxyz(base.rotation),
        )
        self.collision_nodes: list[Any] = []
        self.link_frames: dict[str, Any] = {}
        self.link_nodes: dict[str, str] = {}
        self._tree = LinkTree(robot, node_name)
        self.target_frames: dict[str, Any] = {}
        self._frames: list[tuple[int, Any]] = []
        self._batches: dict[int, tuple[list[tuple[int, Any]], adapter.PoseBatch]] = {}
        self._target_frames: list[tuple[int, Any]] = []
        self.target_root: Any = None  # the ghost is built at the first move
        self._geometry = geometry
        for tree_link in self._tree.links:
            link = tree_link.name
            shapes = geometry.get(link)
            node = self.link_nodes[link] = f"{self.prefix}/links/{tree_link.path}"
            handle = self._scene.add_frame(node, show_axes=False)
            self._frames.append((tree_link.frame_id, handle))
            self.link_frames[link] = handle
            if shapes is None:
                continue
            for k, shape in enumerate(shapes.visual):
                self._add_shape(f"{node}/visual_{k}", shape, visible=True)
            for k, shape in enumerate(shapes.collision):
                self.collision_nodes.append(
                    self._add_shape(f"{node}/collision_{k}", shape, visible=False)
                )
        self._scene.add_frame(
            f"{self.link_nodes[robot.eelink]}/ee", axes_length=0.12, axes_radius=0.005
        )
        self.sent_q: tuple[float, ...] | None = None
        self.sent_ee: pin.SE3 | None = None
        self.sent_target: tuple[float, ...] | None = None

    def draw(self, q: tuple[float, ...], opening: float | None = None) -> pin.SE3:
        """Pose every link frame for chain values ``q`` [rad or m], the gripper's fingers
        at ``opening`` (0 closed .. 1 open; None: where the model's neutral puts them).

        Returns:
            The end effector's placement in the base frame.
        """
        self._pose(self._frames, q, opening)
        self.sent_q = q
        ee = pin.updateFramePlacement(self.robot.model, self._data, self.robot.ee_frame)
        self.sent_ee = self.robot.base_placement.actInv(ee)
        return self.sent_ee

    def link_pose(self, link: str, frames: dict[str, Any] | None = None) -> pin.SE3:
        """``link``'s pose in the root's frame as the page was last told: the product of
        the link frames' poses down its path (``frames``: a copy's, such as
        ``target_frames``; None: ``link_frames``)."""
        frames = self.link_frames if frames is None else frames
        poses: list[pin.SE3] = []
        for tree_link in self._tree.links:
            handle = frames[tree_link.name]
            w, x, y, z = handle.wxyz
            local = pin.SE3(
                pin.Quaternion(w, x, y, z).toRotationMatrix(), np.array(handle.position)
            )
            poses.append(local if tree_link.parent < 0 else poses[tree_link.parent] * local)
            if tree_link.name == link:
                return poses[-1]
        raise KeyError(f"{link!r} is not a link of {self.name}")

    def ee_pose(self, q: tuple[float, ...]) -> pin.SE3:
        """The end effector's placement in the base frame for chain values ``q`` [rad or
        m]: the one drawn last if ``q`` is what it was drawn for (no second FK)."""
        if q == self.sent_q and self.sent_ee is not None:
            return self.sent_ee
        model, data = self.robot.model, self._probe
        pin.forwardKinematics(model, data, self.robot.configuration(q))
        return self.robot.base_placement.actInv(
            pin.updateFramePlacement(model, data, self.robot.ee_frame)
        )

    def show_target(self, target: tuple[float, ...] | None) -> None:
        """Stand the ghost at ``target`` [rad or m]; None hides it."""
        if target == self.sent_target:
            return
        if target is None:
            self.target_root.visible = False
        else:
            if self.target_root is None:
                self.target_root, self._target_frames = self.add_copy("target")
                self.target_frames = {
                    link.name: handle
                    for link, (_, handle) in zip(self._tree.links, self._target_frames)
                }
            self._pose(self._target_frames, target)
            if self.sent_target is None:
                self.target_root.visible = True
        self.sent_target = target

    def add_copy(
        self, segment: str, rgba: tuple[float, float, float, float] | None = None
    ) -> tuple[Any, list[tuple[int, Any]]]:
        """A copy of the arm under ``<prefix>/<segment>`` (hidden): each link's visual
        geometry again, translucent in its colours (``GHOST_OPACITY``), or all in ``rgba``.

        Returns:
            Its root node and its link frames (Pinocchio frame id, node), for ``pose_copy``.
        """
        root = self._scene.add_frame(f"{self.prefix}/{segment}", show_axes=False, visible=False)
        frames = []
        for tree_link in self._tree.links:
            node = f"{self.prefix}/{segment}/{tree_link.path}"
            handle = self._scene.add_frame(node, show_axes=False)
            frames.append((tree_link.frame_id, handle))
            shapes = self._geometry.get(tree_link.name)
            for k, shape in enumerate(shapes.visual if shapes is not None else ()):
                tinted = shape if rgba is None else dataclasses.replace(shape, rgba=rgba)
                self._add_shape(f"{node}/visual_{k}", tinted, visible=True, ghost=rgba is None)
        return root, frames

    def pose_copy(self, frames: list[tuple[int, Any]], q: tuple[float, ...]) -> None:
        """Pose a copy's link frames (``add_copy``) for chain values ``q`` [rad or m]."""
        self._pose(frames, q)

    def add_overlay(self, link: str, rgba: tuple[float, float, float, float]) -> list[Any]:
        """A copy of ``link``'s visual geometry in ``rgba``, over the link (hidden).

        Returns:
            The copy's nodes (one per visual shape; none for a link without shapes).
        """
        node = self.link_nodes[link]
        shapes = self._geometry.get(link)
        nodes = []
        for k, shape in enumerate(shapes.visual if shapes is not None else ()):
            tinted = dataclasses.replace(shape, rgba=rgba)
            nodes.append(self._add_shape(f"{node}/overlay_{k}", tinted, visible=False))
        return nodes

    def show_collision(self, shown: bool) -> None:
        for node in self.collision_nodes:
            node.visible = shown

    def reach(self) -> float:
        """The farthest frame from the root at the neutral pose [m] (for the camera)."""
        pin.framesForwardKinematics(self.robot.model, self._data, self.robot.neutral)
        return max((float(np.linalg.norm(f.translation)) for f in self._data.oMf), default=1.0)

    def _pose(
        self, frames: list[tuple[int, Any]], q: tuple[float, ...], opening: float | None = None
    ) -> None:
        model, data = self.robot.model, self._data
        pin.forwardKinematics(model, data, self.robot.configuration(q, opening))
        held = self._batches.get(id(frames))
        if held is None:  # the list is kept with its batch: its id stays its own
            held = self._batches[id(frames)] = (frames, adapter.PoseBatch([h for _, h in frames]))
        local = self._tree.local
        xyzquat = np.array([pin.SE3ToXYZQUAT(local(link, data)) for link in self._tree.links])
        held[1].queue(xyzquat[:, _WXYZ_ORDER])

    def _add_shape(self, name: str, shape: Shape, visible: bool, ghost: bool = False) -> Any:
        scene = self._scene
        common: dict[str, Any] = {
            "position": shape.origin[:3, 3],
            "wxyz": wxyz(shape.origin[:3, :3]),
            "visible": visible,
        }
        if shape.rgba is None:  # a mesh with colours of its own
            assert shape.mesh is not None
            if ghost:
                rgb, alpha = GHOST_GREY, 1.0
            elif isinstance(shape.mesh, Mesh):  # read by mesh_files: its colour, if it has one
                rgba = shape.mesh.rgba or DEFAULT_RGBA  # (a collision mesh standing in: none)
                rgb, alpha = rgba[:3], rgba[3]
            else:
                return scene.add_mesh_trimesh(name, shape.mesh, **common)
        else:
            rgb, alpha = shape.rgba[:3], shape.rgba[3]
        if ghost:
            alpha = min(alpha, 1.0) * GHOST_OPACITY
            common["cast_shadow"] = False
        common["opacity"] = None if alpha >= 1.0 else alpha
        if shape.kind == "box":
            sx, sy, sz = shape.size
            return scene.add_box(name, color=rgb, dimensions=(sx, sy, sz), **common)
        if shape.kind == "cylinder":
            radius, length = shape.size
            return scene.add_cylinder(name, radius=radius, height=length, color=rgb, **common)
        if shape.kind == "sphere":
            return scene.add_icosphere(name, radius=shape.size[0], color=rgb, **common)
        mesh = shape.mesh
        assert mesh is not None
        return scene.add_mesh_simple(name, mesh.vertices, mesh.faces, color=rgb, **common)
