"""The bundled robot URDFs match the kinematic figures they were written from."""

from pathlib import Path

import numpy as np
import pinocchio
import pytest
import yourdfpy
from support import ROOT

ROBOTS_DIR = ROOT / "robots"

A = 2.96705972839
B = 2.09439510239

# name -> expected figures. Joints: (name, type, parent, child, xyz, rpy, axis,
# (lower, upper, velocity, effort) or None for fixed joints).
# fmt: off
ROBOTS = {
    "motoman_sia20d": {
        "robot_name": "motoman_sia20d",
        "nq": 7,
        "eelink": "link_t",
        "ee_at_zero": (0.0, 0.0, 1.50),
        "joints": [
            ("joint_s", "revolute", "base_link", "link_s", (0, 0, 0.41), (0, 0, 0),
             (0, 0, 1), (-3.1416, 3.1416, 2.26, 100)),
            ("joint_l", "revolute", "link_s", "link_l", (0, 0, 0), (0, 0, 0),
             (0, 1, 0), (-1.91, 1.91, 2.26, 100)),
            ("joint_e", "revolute", "link_l", "link_e", (0, 0, 0.49), (0, 0, 0),
             (0, 0, 1), (-2.96, 2.96, 2.96, 100)),
            ("joint_u", "revolute", "link_e", "link_u", (0, 0, 0), (0, 0, 0),
             (0, -1, 0), (-2.26, 2.26, 2.96, 100)),
            ("joint_r", "revolute", "link_u", "link_r", (0, 0, 0.42), (0, 0, 0),
             (0, 0, -1), (-3.1416, 3.1416, 3.48, 100)),
            ("joint_b", "revolute", "link_r", "link_b", (0, 0, 0), (0, 0, 0),
             (0, -1, 0), (-1.91, 1.91, 3.48, 100)),
            ("joint_t", "revolute", "link_b", "link_t", (0, 0, 0.18), (0, 0, 0),
             (0, 0, -1), (-3.1416, 3.1416, 6.97, 100)),
            ("link_t-tool0", "fixed", "link_t", "tool0", (0, 0, 0), (0, 0, -3.1416),
             None, None),
        ],
    },
    "fanuc_lrmate200id": {
        "robot_name": "fanuc_lrmate200id",
        "nq": 8,  # the arm's 6, and its gripper's two fingers (ours, not FANUC's)
        "eelink": "link_6",
        "ee_at_zero": (0.465, 0.0, 0.695),
        # Effort is not among the published figures; the URDF leaves it 0 (unspecified).
        "joints": [
            ("joint_1", "revolute", "base_link", "link_1", (0, 0, 0.330), (0, 0, 0),
             (0, 0, 1), (-2.965, 2.965, 7.85, 0)),
            ("joint_2", "revolute", "link_1", "link_2", (0.050, 0, 0), (0, 0, 0),
             (0, 1, 0), (-1.745329, 2.530727, 6.63, 0)),
            ("joint_3", "revolute", "link_2", "link_3", (0, 0, 0.330), (0, 0, 0),
             (0, -1, 0), (-2.450966, 4.886922, 9.08, 0)),
            ("joint_4", "revolute", "link_3", "link_4", (0, 0, 0.035), (0, 0, 0),
             (-1, 0, 0), (-3.315, 3.315, 9.60, 0)),
            ("joint_5", "revolute", "link_4", "link_5", (0.335, 0, 0), (0, 0, 0),
             (0, -1, 0), (-2.18, 2.18, 9.51, 0)),
            ("joint_6", "revolute", "link_5", "link_6", (0.080, 0, 0), (0, 0, 0),
             (1, 0, 0), (-6.285, 6.285, 17.45, 0)),
            ("joint_6-tool0", "fixed", "link_6", "tool0", (0, 0, 0),
             (3.1415926535, -1.570796327, 0), None, None),
            ("base_link-base", "fixed", "base_link", "base", (0, 0, 0.330), (0, 0, 0),
             None, None),
            ("link_6-gripper_hand", "fixed", "link_6", "gripper_hand", (0, 0, 0), (0, 0, 0),
             None, None),
            ("gripper_finger_left_joint", "prismatic", "gripper_hand", "gripper_finger_left",
             (0.04, 0.001, 0), (0, 0, 0), (0, 1, 0), (0, 0.03, 0.1, 0)),
            ("gripper_finger_right_joint", "prismatic", "gripper_hand", "gripper_finger_right",
             (0.04, -0.001, 0), (0, 0, 0), (0, -1, 0), (0, 0.03, 0.1, 0)),
        ],
    },
    "kuka_lwr": {
        "robot_name": "lwr",
        "nq": 7,
        "eelink": "lwr_7_link",
        "ee_at_zero": (0.0, 0.0, 1.1785),
        "joints": [
            ("world_lwr_base_joint", "fixed", "world", "lwr_base_link", (0, 0, 0), (0, 0, 0),
             None, None),
            ("lwr_0_joint", "revolute", "lwr_base_link", "lwr_1_link", (0, 0, 0.11), (0, 0, 0),
             (0, 0, 1), (-A, A, 1.91986217719, 176)),
            ("lwr_1_joint", "revolute", "lwr_1_link", "lwr_2_link", (0, 0, 0.2005), (0, 0, 0),
             (0, -1, 0), (-B, B, 1.91986217719, 176)),
            ("lwr_2_joint", "revolute", "lwr_2_link", "lwr_3_link", (0, 0, 0.20), (0, 0, 0),
             (0, 0, 1), (-A, A, 2.23402144255, 100)),
            ("lwr_3_joint", "revolute", "lwr_3_link", "lwr_4_link", (0, 0, 0.20), (0, 0, 0),
             (0, 1, 0), (-B, B, 2.23402144255, 100)),
            ("lwr_4_joint", "revolute", "lwr_4_link", "lwr_5_link", (0, 0, 0.20), (0, 0, 0),
             (0, 0, 1), (-A, A, 3.56047167407, 100)),
            ("lwr_5_joint", "revolute", "lwr_5_link", "lwr_6_link", (0, 0, 0.19), (0, 0, 0),
             (0, -1, 0), (-B, B, 3.21140582367, 38)),
            ("lwr_6_joint", "revolute", "lwr_6_link", "lwr_7_link", (0, 0, 0.078), (0, 0, 0),
             (0, 0, 1), (-A, A, 3.21140582367, 38)),
        ],
    },
}
# fmt: on

NAMES = list(ROBOTS)


def urdf_path(name: str) -> Path:
    return ROBOTS_DIR / name / "robot.urdf"


def movable(name: str):
    return [j for j in ROBOTS[name]["joints"] if j[1] != "fixed"]


@pytest.fixture(scope="module", params=NAMES, ids=NAMES)
def robot(request):
    name = request.param
    model = pinocchio.buildModelFromUrdf(str(urdf_path(name)))
    return name, ROBOTS[name], model


def test_dof_and_joint_order(robot):
    name, facts, model = robot
    assert model.nq == facts["nq"]
    assert list(model.names[1:]) == [j[0] for j in movable(name)]


def test_end_effector_at_zero(robot):
    _, facts, model = robot
    data = model.createData()
    pinocchio.framesForwardKinematics(model, data, pinocchio.neutral(model))
    assert model.existFrame(facts["eelink"])
    placement = data.oMf[model.getFrameId(facts["eelink"])]
    np.testing.assert_allclose(placement.translation, facts["ee_at_zero"], rtol=0, atol=1e-9)


def test_limits(robot):
    name, _, model = robot
    lim = np.array([j[7] for j in movable(name)], dtype=float)
    np.testing.assert_allclose(model.lowerPositionLimit, lim[:, 0], rtol=0, atol=1e-12)
    np.testing.assert_allclose(model.upperPositionLimit, lim[:, 1], rtol=0, atol=1e-12)
    np.testing.assert_allclose(model.velocityLimit, lim[:, 2], rtol=0, atol=1e-12)
    np.testing.assert_allclose(model.effortLimit, lim[:, 3], rtol=0, atol=1e-12)


@pytest.mark.parametrize("name", NAMES, ids=NAMES)
def test_yourdfpy_tree_matches_table(name):
    urdf = yourdfpy.URDF.load(str(urdf_path(name)))
    facts = ROBOTS[name]
    assert urdf.robot.name == facts["robot_name"]
    assert sorted(urdf.joint_map) == sorted(j[0] for j in facts["joints"])
    for jname, jtype, parent, child, xyz, rpy, axis, limits in facts["joints"]:
        joint = urdf.joint_map[jname]
        assert (joint.type, joint.parent, joint.child) == (jtype, parent, child), jname
        expected = np.eye(4)
        expected[:3, :3] = pinocchio.rpy.rpyToMatrix(*rpy)
        expected[:3, 3] = xyz
        np.testing.assert_allclose(joint.origin, expected, rtol=0, atol=1e-12, err_msg=jname)
        if axis is not None:
            np.testing.assert_allclose(joint.axis, axis, rtol=0, atol=0, err_msg=jname)
        if limits is not None:
            got = (joint.limit.lower, joint.limit.upper, joint.limit.velocity, joint.limit.effort)
            np.testing.assert_allclose(got, limits, rtol=0, atol=1e-12, err_msg=jname)


@pytest.mark.parametrize("name", NAMES, ids=NAMES)
def test_every_moving_link_is_drawn(name):
    urdf = yourdfpy.URDF.load(str(urdf_path(name)))
    for joint in movable(name):
        link = urdf.link_map[joint[3]]
        assert link.visuals, f"{link.name} has no visual"
        assert link.collisions, f"{link.name} has no collision"
        assert link.inertial is not None and link.inertial.mass > 0, link.name
        named = {m.name for m in urdf.robot.materials}
        for visual in link.visuals:
            assert visual.material is not None and visual.material.name in named, link.name


@pytest.mark.parametrize("name", NAMES, ids=NAMES)
def test_geometry_spans_the_arm(name):
    """At zero joints the drawn arm stands on z = 0 and reaches the end-effector."""
    urdf = yourdfpy.URDF.load(str(urdf_path(name)))
    lo, hi = urdf.scene.bounds
    ee = np.array(ROBOTS[name]["ee_at_zero"])
    assert lo[2] == pytest.approx(0.0, abs=1e-6)
    assert ee[2] - 1e-6 <= hi[2] <= ee[2] + 0.1
    assert hi[0] >= ee[0] - 1e-6


# yourdfpy builds the collision scene through trimesh's deprecated Scene.dump(concatenate=True).
@pytest.mark.filterwarnings(r"ignore:`Scene\.dump\(concatenate=True\)`:DeprecationWarning")
@pytest.mark.parametrize("name", NAMES, ids=NAMES)
def test_collision_geometry_loads(name):
    urdf = yourdfpy.URDF.load(
        str(urdf_path(name)), build_collision_scene_graph=True, load_collision_meshes=True
    )
    lo, hi = urdf.collision_scene.bounds
    assert hi[2] >= ROBOTS[name]["ee_at_zero"][2]
