"""A robot's links as the URDF's tree: each link's parent link, its node path in the
page, and its pose in its parent link's frame from Pinocchio's joint placements.

The page nests each link's frame node under its parent link's, so a joint's turn
moves one node: the child's orientation changes, its position in the parent's frame
(the joint's origin) does not, and what hangs below follows in the browser. The
pose in the parent's frame is read from Pinocchio's ``liMi`` (each joint in its
parent joint's frame) rather than ``oMf[parent]^-1 * oMf[child]``: a revolute joint's
position then comes out bit for bit the same each frame, so it is never sent again
(``adapter.PoseBatch`` sends what differs, exactly).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

import pinocchio as pin

from ..robot.model import Robot


@dataclasses.dataclass(frozen=True)
class TreeLink:
    """One link in the tree.

    Attributes:
        name: The link's name (a Pinocchio body frame).
        parent: Its parent link's index in ``LinkTree.links`` (-1: the root link).
        path: Its node path below the robot's links node, ``a/b/c`` (node name segments).
        frame_id: Its Pinocchio frame id.
        joints: The Pinocchio joints between the parent link's joint and its own, in
            order from the parent's side (empty: both hang from one joint).
        before: The parent link's placement in its joint's frame, inverted (None:
            the identity).
        after: Its placement in its joint's frame (None: the identity).
    """

    name: str
    parent: int
    path: str
    frame_id: int
    joints: tuple[int, ...]
    before: pin.SE3 | None
    after: pin.SE3 | None


def _body_parent(model: pin.Model, frame_id: int) -> int:
    """The body frame above ``frame_id`` (-1: none)."""
    frames = model.frames
    here = frames[frame_id].parentFrame
    while here != 0 and frames[here].type != pin.FrameType.BODY:
        here = frames[here].parentFrame
    return here if here != 0 and frames[here].type == pin.FrameType.BODY else -1


def _or_none(placement: pin.SE3) -> pin.SE3 | None:
    return None if placement.isIdentity(0.0) else placement


class LinkTree:
    """A robot's links as a tree, parents before children; see the module docstring.

    Attributes:
        links: The links, each after its parent.
    """

    def __init__(self, robot: Robot, segment: Callable[[str], str]) -> None:
        """``segment``: a link name as one node name segment (``robot_view.node_name``)."""
        model = robot.model
        ids = {link: model.getFrameId(link, pin.BODY) for link in robot.link_names()}
        by_frame = {frame_id: link for link, frame_id in ids.items()}
        parent_of = {link: by_frame.get(_body_parent(model, fid)) for link, fid in ids.items()}
        order: list[str] = []
        placed: set[str] = set()

        def place(link: str) -> None:
            if link in placed:
                return
            above = parent_of[link]
            if above is not None:
                place(above)
            placed.add(link)
            order.append(link)

        for link in ids:
            place(link)
        index = {link: k for k, link in enumerate(order)}
        self.links: list[TreeLink] = []
        for link in order:
            frame = model.frames[ids[link]]
            above = parent_of[link]
            up = self.links[index[above]] if above is not None else None
            parent_frame = model.frames[up.frame_id] if up is not None else None
            stop = int(parent_frame.parentJoint) if parent_frame is not None else 0
            joints: list[int] = []
            j = int(frame.parentJoint)
            while j != stop and j != 0:
                joints.append(j)
                j = int(model.parents[j])
            before = None if parent_frame is None else _or_none(parent_frame.placement.inverse())
            self.links.append(
                TreeLink(
                    link,
                    -1 if above is None else index[above],
                    segment(link) if up is None else f"{up.path}/{segment(link)}",
                    ids[link],
                    tuple(reversed(joints)),
                    before,
                    _or_none(frame.placement),
                )
            )

    def local(self, link: TreeLink, data: pin.Data) -> pin.SE3:
        """``link``'s pose in its parent link's frame (the root link's: in the model's
        root frame), from ``data`` after ``pin.forwardKinematics``."""
        if link.before is None and link.after is None and len(link.joints) == 1:
            return data.liMi[link.joints[0]]  # most links: the joint's placement alone
        pose: pin.SE3 | None = None
        for j in link.joints:
            pose = data.liMi[j] if pose is None else pose * data.liMi[j]
        if link.before is not None:
            pose = link.before if pose is None else link.before * pose
        if link.after is not None:
            pose = link.after if pose is None else pose * link.after
        return pin.SE3.Identity() if pose is None else pose
