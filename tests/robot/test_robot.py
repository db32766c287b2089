"""The chain Pinocchio gives for each bundled robot, and the errors for bad chains."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from support import ROBOTS, ROOT, load_robot

from c2rviz.errors import RobotError
from c2rviz.robot.model import Robot

CHAINS = {
    "motoman_sia20d": (
        "motoman_sia20d",
        ["joint_s", "joint_l", "joint_e", "joint_u", "joint_r", "joint_b", "joint_t"],
        (0.0, 0.0, 1.50),
    ),
    "fanuc_lrmate200id": (
        "fanuc_lrmate200id",
        ["joint_1", "joint_2", "joint_3", "joint_4", "joint_5", "joint_6"],
        (0.465, 0.0, 0.695),
    ),
    "kuka_lwr": ("lwr", [f"lwr_{i}_joint" for i in range(7)], (0.0, 0.0, 1.1785)),
}


@pytest.mark.parametrize("name", CHAINS, ids=list(CHAINS))
def test_chain_names_order_and_home_pose(name):
    robot = load_robot(name)
    robot_name, joints, ee_at_zero = CHAINS[name]
    assert robot.name == robot_name
    assert list(robot.joint_names) == joints
    assert robot.ee_pose([0.0] * robot.n).translation == pytest.approx(ee_at_zero, abs=1e-12)


@pytest.mark.parametrize("name", CHAINS, ids=list(CHAINS))
def test_ee_pose_is_pinocchio_fk_in_the_base_frame(name):
    robot = load_robot(name)
    model = robot.model
    data = model.createData()
    rng = np.random.default_rng(7)
    for _ in range(20):
        q = robot.random(rng)
        pin.framesForwardKinematics(model, data, robot.configuration(q))
        expected = data.oMf[robot.base_frame].actInv(data.oMf[robot.ee_frame])
        assert robot.ee_pose(q).isApprox(expected, 1e-12)


def test_limits_come_from_the_urdf():
    robot = load_robot("fanuc_lrmate200id")
    assert robot.lower[2] == pytest.approx(-2.450966)
    assert robot.upper[2] == pytest.approx(4.886922)


def test_one_chain_tree_needs_no_ends():
    robot = Robot.from_urdf(ROOT / ROBOTS["kuka_lwr"][0])
    assert (robot.base, robot.eelink) == ("world", "lwr_7_link")
    assert robot.n == 7


def test_a_branching_tree_lists_the_candidate_end_links():
    with pytest.raises(RobotError, match=r"candidate end links: base, tool0"):
        Robot.from_urdf(ROOT / ROBOTS["fanuc_lrmate200id"][0])


def test_unknown_link_names_the_links():
    with pytest.raises(RobotError, match=r"eelink link 'hand' is not in motoman_sia20d.*link_t"):
        Robot.from_urdf(ROOT / ROBOTS["motoman_sia20d"][0], "base_link", "hand")


def test_eelink_must_be_below_base():
    with pytest.raises(RobotError, match="is not below base"):
        Robot.from_urdf(ROOT / ROBOTS["motoman_sia20d"][0], "link_t", "link_s")


def test_a_sub_chain_is_indexed_from_its_base():
    robot = Robot.from_urdf(ROOT / ROBOTS["motoman_sia20d"][0], "link_e", "link_b")
    assert robot.joint_names == ("joint_u", "joint_r", "joint_b")
    assert robot.ee_pose([0.0] * 3).translation == pytest.approx((0, 0, 0.42))


def test_missing_and_broken_urdf(tmp_path):
    with pytest.raises(RobotError, match="does not exist"):
        Robot.from_urdf(tmp_path / "nope.urdf")
    broken = tmp_path / "broken.urdf"
    broken.write_text("<robot name='x'><link name='a'/><joint name='j'")
    with pytest.raises(RobotError, match="cannot read the URDF"):
        Robot.from_urdf(broken)
