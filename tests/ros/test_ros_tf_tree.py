"""Our robot as ROS TF: checked against Pinocchio's FK and against the URDF's own numbers."""

from __future__ import annotations

import dataclasses
import math
import xml.etree.ElementTree as ET

import numpy as np
import pinocchio as pin
import pytest
from ros_helpers import ROBOTS, robot_named, tree_robot

from c2rviz.robot import Robot
from c2rviz.ros.errors import DescriptionError
from c2rviz.ros.tf_tree import TfTree, Transform, urdf_joints

TOLERANCE = 1e-9


def se3(item: Transform) -> pin.SE3:
    _, _, translation, (x, y, z, w) = item
    return pin.SE3(pin.Quaternion(w, x, y, z).toRotationMatrix(), np.array(translation))


def link_poses(root: str, transforms: list[Transform]) -> dict[str, pin.SE3]:
    """Every frame's pose in ``root``, composing the TF tree as a TF listener would."""
    children: dict[str, list[Transform]] = {}
    for item in transforms:
        children.setdefault(item[0], []).append(item)
    poses = {root: pin.SE3.Identity()}
    stack = [root]
    while stack:
        parent = stack.pop()
        for item in children.get(parent, []):
            assert item[1] not in poses, f"{item[1]} has two parents"
            poses[item[1]] = poses[parent] * se3(item)
            stack.append(item[1])
    return poses


def close(a: pin.SE3, b: pin.SE3) -> bool:
    return bool(np.allclose(a.homogeneous, b.homogeneous, rtol=0, atol=TOLERANCE))


@pytest.mark.parametrize("name", ROBOTS)
def test_tf_chain_from_base_to_ee_is_the_ee_pose(name: str) -> None:
    robot = robot_named(name)
    tree = TfTree(robot)
    rng = np.random.default_rng(7)
    for _ in range(5):
        q = robot.random(rng)
        full = robot.configuration(q)
        transforms = tree.static_transforms() + tree.moving_transforms(full)
        poses = link_poses(robot.base, transforms)
        assert close(poses[robot.eelink], robot.ee_pose(q)), name


@pytest.mark.parametrize("name", ROBOTS)
def test_every_link_where_pinocchio_puts_it(name: str) -> None:
    """From the root, the TF tree reaches every link, each at Pinocchio's frame placement."""
    robot = robot_named(name)
    tree = TfTree(robot)
    q = robot.random(np.random.default_rng(3))
    full = robot.configuration(q)
    poses = link_poses(tree.root, tree.static_transforms() + tree.moving_transforms(full))
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, full)
    root = data.oMf[robot.model.getFrameId(tree.root, pin.BODY)]
    assert set(poses) == set(robot.link_names())
    for link, pose in poses.items():
        assert close(pose, root.actInv(data.oMf[robot.model.getFrameId(link, pin.BODY)])), link


def urdf_transform(joint: ET.Element, position: float) -> pin.SE3:
    """What robot_state_publisher computes for one joint: origin, then the motion."""
    origin = joint.find("origin")
    xyz = [
        float(v) for v in (origin.get("xyz", "0 0 0") if origin is not None else "0 0 0").split()
    ]
    rpy = [
        float(v) for v in (origin.get("rpy", "0 0 0") if origin is not None else "0 0 0").split()
    ]
    axis_element = joint.find("axis")
    axis = np.array(
        [
            float(v)
            for v in (
                axis_element.get("xyz", "1 0 0") if axis_element is not None else "1 0 0"
            ).split()
        ]
    )
    axis /= np.linalg.norm(axis)
    placement = pin.SE3(pin.rpy.rpyToMatrix(*rpy), np.array(xyz))
    if joint.get("type") == "prismatic":
        motion = pin.SE3(np.eye(3), axis * position)
    else:
        motion = pin.SE3(pin.AngleAxis(position, axis).toRotationMatrix(), np.zeros(3))
    return placement * motion


@pytest.mark.parametrize("name", ROBOTS)
def test_joint_states_and_tf_agree_as_ros_reads_them(name: str) -> None:
    """Each /tf transform is the URDF origin moved by the /joint_states position (rsp's sum)."""
    robot = robot_named(name)
    tree = TfTree(robot)
    full = robot.configuration(robot.random(np.random.default_rng(11)))
    names, positions = tree.joint_positions(full)
    elements = {j.get("name"): j for j in ET.fromstring(robot.source.xml).findall("joint")}
    moving = {item[1]: item for item in tree.moving_transforms(full)}
    assert len(moving) == len(names)
    for joint_name, position in zip(names, positions):
        element = elements[joint_name]
        child = element.find("child").get("link", "")  # type: ignore[union-attr]
        assert close(se3(moving[child]), urdf_transform(element, position)), joint_name


def test_tree_robot_continuous_mimic_and_off_chain() -> None:
    robot = tree_robot()
    tree = TfTree(robot)
    assert tree.names == (
        "lift",
        "shoulder",
        "elbow",
        "wrist",
        "finger_left_joint",
        "finger_right_joint",
        "camera_pan",
    )
    assert [j.name for j in tree.fixed] == ["tool_joint", "mast_joint"]
    q = [0.3, 0.5, -1.0, 4.0]  # the wrist (continuous) past pi
    names, positions = tree.joint_positions(robot.configuration(q))
    by_name = dict(zip(names, positions))
    assert by_name["lift"] == 0.3 and by_name["elbow"] == -1.0
    assert by_name["wrist"] == pytest.approx(4.0 - 2 * math.pi, abs=1e-12)  # (-pi, pi]
    assert by_name["finger_left_joint"] == 0.0  # off the chain: neutral
    assert by_name["finger_right_joint"] == pytest.approx(-1 * 0.0 + 0.002, abs=1e-15)
    assert by_name["camera_pan"] == 0.5  # its limits exclude 0: the nearest limit
    velocities = tree.joint_velocities([0.1, 0.2, 0.3, 0.4])
    assert dict(zip(names, velocities)) == {
        "lift": 0.1,
        "shoulder": 0.2,
        "elbow": 0.3,
        "wrist": 0.4,
        "finger_left_joint": 0.0,
        "finger_right_joint": -0.0,
        "camera_pan": 0.0,
    }


def test_panda_names_fingers_mimic_and_fixed_joints() -> None:
    robot = robot_named("panda")
    tree = TfTree(robot, prefix="left/")
    assert tree.names == (
        *(f"panda_joint{i}" for i in range(1, 8)),
        "panda_finger_joint1",
        "panda_finger_joint2",
    )
    assert [j.name for j in tree.fixed] == [
        "panda_joint8",
        "panda_hand_joint",
        "panda_hand_tcp_joint",
    ]
    assert tree.root == "left/panda_link0"
    assert {(p, c) for p, c, _, _ in tree.static_transforms()} == {
        ("left/panda_link7", "left/panda_link8"),
        ("left/panda_link8", "left/panda_hand"),
        ("left/panda_hand", "left/panda_hand_tcp"),
    }
    # Open the fingers (off the chain) by hand: the mimic finger follows, as rsp computes it.
    full = robot.configuration(robot.home)
    finger = robot.model.joints[robot.model.getJointId("panda_finger_joint1")]
    full[finger.idx_q] = 0.03
    _, positions = tree.joint_positions(full)
    assert positions[-2:] == [0.03, 0.03]
    moving = {c: item for item in tree.moving_transforms(full) for c in [item[1]]}
    assert moving["left/panda_rightfinger"][0] == "left/panda_hand"
    assert moving["left/panda_rightfinger"][2][1] == pytest.approx(-0.03, abs=TOLERANCE)


@pytest.mark.parametrize(
    ("xml", "problem"),
    [
        ('<?xml version="1.0"?><!DOCTYPE r [<!ENTITY a "b">]><robot name="r"/>', "DOCTYPE"),
        (
            "<robot name='r'><joint name='j' type='fixed'><parent link='a'/></joint></robot>",
            "needs a type",
        ),
        (
            "<robot name='r'><joint name='j' type='hinge'><parent link='a'/><child link='b'/>"
            "</joint></robot>",
            "needs a type",
        ),
        ("<robot name='r'><joint", "not XML"),
        (
            "<robot name='r'><joint name='j' type='revolute'><parent link='a'/><child link='b'/>"
            "<mimic joint='k' multiplier='two'/></joint></robot>",
            "mimic number",
        ),
    ],
    ids=["doctype", "no-child", "unknown-type", "not-xml", "mimic-number"],
)
def test_bad_descriptions(xml: str, problem: str) -> None:
    with pytest.raises(DescriptionError, match=problem):
        urdf_joints(xml)


def test_urdf_joints_reads_mimic_defaults() -> None:
    joints = urdf_joints(
        "<robot name='r'><link name='a'/><link name='b'/>"
        "<joint name='j' type='prismatic'><parent link='a'/><child link='b'/>"
        "<mimic joint='k'/></joint>"
        "<gazebo><joint name='not-a-urdf-joint'/></gazebo></robot>"
    )
    assert [
        (j.name, j.kind, j.parent, j.child, j.mimic, j.multiplier, j.offset) for j in joints
    ] == [("j", "prismatic", "a", "b", "k", 1.0, 0.0)]


def test_a_model_that_is_not_the_urdf_is_refused() -> None:
    robot = robot_named("motoman_sia20d")
    renamed = dataclasses.replace(robot.source, xml=robot.source.xml.replace("link_s", "link_z"))
    other = Robot(robot.model, robot.base, robot.eelink, renamed)
    with pytest.raises(DescriptionError, match="not in the model"):
        TfTree(other)
