"""The link frames nested as the URDF's tree: composed down each path they are
Pinocchio's FK, and a revolute joint's turn leaves its child's position bit for bit
the same (so the page is sent an orientation only)."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from support import ROBOTS, load_robot

from c2rviz.view.link_tree import LinkTree
from c2rviz.view.robot_view import node_name


def in_root(tree: LinkTree, data: pin.Data) -> list[pin.SE3]:
    poses: list[pin.SE3] = []
    for link in tree.links:
        local = tree.local(link, data)
        poses.append(local if link.parent < 0 else poses[link.parent] * local)
    return poses


@pytest.mark.parametrize("name", list(ROBOTS))
def test_the_nested_frames_compose_to_pinocchio_fk(name: str) -> None:
    robot = load_robot(name)
    tree = LinkTree(robot, node_name)
    assert sorted(link.name for link in tree.links) == sorted(robot.link_names())
    data = robot.model.createData()
    rng = np.random.default_rng(5)
    for _ in range(20):
        pin.framesForwardKinematics(robot.model, data, robot.configuration(robot.random(rng)))
        for link, pose in zip(tree.links, in_root(tree, data)):
            assert pose.isApprox(data.oMf[link.frame_id], 1e-12), link.name
            if link.parent >= 0:  # a child's node path is its parent's and its own name
                assert link.path == f"{tree.links[link.parent].path}/{node_name(link.name)}"


def test_a_revolute_joints_turn_moves_no_position() -> None:
    robot = load_robot("motoman_sia20d")
    tree = LinkTree(robot, node_name)
    data = robot.model.createData()
    rng = np.random.default_rng(6)
    seen = []
    for _ in range(2):
        pin.forwardKinematics(robot.model, data, robot.configuration(robot.random(rng)))
        seen.append([(tree.local(link, data).translation.copy()) for link in tree.links])
    for link, before, after in zip(tree.links, *seen):
        assert np.array_equal(before, after), link.name  # exactly: never sent again
