"""A robot's gripper: found among the URDF's finger joints, or named by the ini."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from support import load_robot

from c2rviz.app.ini_world import gripper_from
from c2rviz.errors import ConfigError
from c2rviz.robot.catalogue import example_robots
from c2rviz.robot.model import Robot


def panda() -> Robot:
    entry = example_robots()["panda"]
    return Robot.from_urdf(entry.urdf, entry.base, entry.eelink, package_paths=entry.package_paths)


def test_the_bundled_fanuc_has_a_parallel_gripper_off_its_chain() -> None:
    robot = load_robot("fanuc_lrmate200id")
    gripper = robot.gripper
    assert gripper is not None
    assert gripper.name == "gripper_hand"
    assert gripper.joints == ("gripper_finger_left_joint",)  # the right one mimics it
    assert (gripper.closed, gripper.opened) == ((0.0,), (0.03,))
    assert gripper.stroke_s == pytest.approx(0.3)  # 30 mm at 0.1 m/s
    assert robot.n == 6 and "gripper_finger_left_joint" not in robot.joint_names
    assert gripper.separation(0.0) == 0.0
    assert gripper.separation(0.5) == pytest.approx(0.03)
    assert gripper.separation(1.0) == pytest.approx(0.06)


def test_motoman_and_kuka_have_none() -> None:
    assert load_robot("motoman_sia20d").gripper is None
    assert load_robot("kuka_lwr").gripper is None


def test_the_opening_moves_both_fingers_and_nothing_else() -> None:
    robot = load_robot("fanuc_lrmate200id")
    q = robot.home
    model, data = robot.model, robot.model.createData()
    left = model.getFrameId("gripper_finger_left", pin.BODY)
    right = model.getFrameId("gripper_finger_right", pin.BODY)
    spots = {}
    for opening in (0.0, 1.0):
        pin.framesForwardKinematics(model, data, robot.configuration(q, opening))
        spots[opening] = (data.oMf[left].translation.copy(), data.oMf[right].translation.copy())
    apart = {k: float(np.linalg.norm(a - b)) for k, (a, b) in spots.items()}
    assert apart[1.0] - apart[0.0] == pytest.approx(0.06)
    np.testing.assert_array_equal(robot.configuration(q), robot.configuration(q, 0.0))
    ee = robot.ee_pose(q)
    assert ee.isApprox(robot.ee_pose(q))  # the chain's end does not depend on the fingers


def test_the_panda_fingers_of_example_robot_data() -> None:
    robot = panda()
    gripper = robot.gripper
    assert gripper is not None and gripper.joints == ("panda_finger_joint1",)
    assert gripper.name == "panda_hand"
    assert gripper.separation(1.0) == pytest.approx(0.08)  # 2 x 40 mm, the mimic follows
    full = robot.configuration(robot.home, 0.5)
    assert full[gripper.idx_q[0]] == pytest.approx(0.02)


def test_the_ini_names_the_fingers_or_none() -> None:
    robot = load_robot("fanuc_lrmate200id")
    spec = {"gripper": "gripper_finger_left_joint:0.01:0.02"}
    gripper = gripper_from("fanuc", spec, robot)
    assert gripper is not None and (gripper.closed, gripper.opened) == ((0.01,), (0.02,))
    assert gripper.separation(1.0) == pytest.approx(0.02)
    assert gripper_from("fanuc", {"gripper": "none"}, robot) is None
    assert gripper_from("fanuc", {}, robot) is robot.gripper


@pytest.mark.parametrize(
    ("text", "words"),
    [
        ("gripper_finger_left_joint", "must be JOINT:CLOSED:OPEN"),
        ("gripper_finger_left_joint:0:x", "not a comma-separated list of numbers"),
        ("gripper_finger_left_joint:0:nan", "not a finite number"),
        ("no_such_joint:0:1", "'no_such_joint' is not in fanuc_lrmate200id"),
        ("joint_6:0:90", "'joint_6' is a joint of the chain, not a finger"),
        ("gripper_finger_right_joint:0:0.03", "a mimic joint follows its leader"),
        ("gripper_finger_left_joint:0.01:0.01", "closed and open values are the same"),
    ],
    ids=["no-values", "not-a-number", "nan", "unknown", "chain", "mimic", "same"],
)
def test_a_bad_ini_gripper_names_section_and_key(text: str, words: str) -> None:
    with pytest.raises(ConfigError, match="fanuc") as caught:
        gripper_from("fanuc", {"gripper": text}, load_robot("fanuc_lrmate200id"))
    assert "[fanuc] gripper" in str(caught.value)
    assert words in str(caught.value)
