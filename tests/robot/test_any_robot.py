"""Any user's robot: example-robot-data arms, trees, mimic, prismatic and continuous joints.

The example-robot-data tests skip when that package is not installed (it is in
the ``test`` extra).
"""

from __future__ import annotations

import logging
import math
import shutil
from collections.abc import Callable, Iterator
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
import yourdfpy
from support import ROOT, Client, ServerThread

from c2rviz.app import cli
from c2rviz.app.config import ServerLimits, load_settings
from c2rviz.errors import ConfigError, RobotError
from c2rviz.ini import find_ini
from c2rviz.motion.limits import motion_limits
from c2rviz.robot.catalogue import EXAMPLE_ROBOTS, example_robot_data_dir, example_robots
from c2rviz.robot.model import CONTINUOUS_LIMIT, Robot

DATA = ROOT / "tests" / "data"
TREE = DATA / "tree_robot" / "tree.urdf"
LIMITS_URDF = DATA / "limits_robot" / "limits.urdf"
TINY_PACKAGE = DATA / "tiny_ws" / "src" / "tiny_description"

needs_erd = pytest.mark.skipif(
    example_robot_data_dir() is None, reason="example-robot-data is not installed"
)


def pinocchio_chain(model: pin.Model, base: str, eelink: str) -> list[str]:
    """The movable joints between two links, as Pinocchio's ``supports`` lists them."""
    base_joint = model.frames[model.getFrameId(base, pin.BODY)].parentJoint
    ee_joint = model.frames[model.getFrameId(eelink, pin.BODY)].parentJoint
    below_base = set(model.supports[base_joint])
    return [
        model.names[j]
        for j in model.supports[ee_joint]
        if j not in below_base and model.joints[j].nq > 0
    ]


def erd_robot(name: str) -> Robot:
    entry = example_robots()[name]
    return Robot.from_urdf(entry.urdf, entry.base, entry.eelink, package_paths=entry.package_paths)


# --- example-robot-data ---------------------------------------------------------------


@needs_erd
@pytest.mark.parametrize("name", sorted(EXAMPLE_ROBOTS))
def test_example_robot_loads_with_its_meshes(name: str) -> None:
    robot = erd_robot(name)
    assert robot.source.mesh_uris(), f"{name} has no meshes to check"
    assert robot.source.missing_meshes() == []
    assert list(robot.joint_names) == pinocchio_chain(robot.model, robot.base, robot.eelink)


@needs_erd
def test_panda_fingers_mimic_and_chain() -> None:
    robot = erd_robot("panda")
    assert robot.joint_names == tuple(f"panda_joint{i}" for i in range(1, 8))
    model = robot.model
    mimic = model.joints[model.getJointId("panda_finger_joint2")]
    assert mimic.nq == 0  # follows panda_finger_joint1; no configuration entry of its own
    to_finger = Robot(model, "panda_link0", "panda_leftfinger", robot.source)
    assert to_finger.joint_names[-1] == "panda_finger_joint1" and to_finger.prismatic[-1]
    to_mimic = Robot(model, "panda_link0", "panda_rightfinger", robot.source)
    assert "panda_finger_joint2" not in to_mimic.joint_names and to_mimic.n == 7
    # opening the left finger by 3 cm opens the right one too
    q = list(to_finger.configuration([0.0] * 7 + [0.03]))
    data = model.createData()
    pin.framesForwardKinematics(model, data, np.array(q))
    left = data.oMf[model.getFrameId("panda_leftfinger")].translation
    right = data.oMf[model.getFrameId("panda_rightfinger")].translation
    assert np.linalg.norm(left - right) == pytest.approx(0.06, abs=1e-9)


@needs_erd
def test_ur5_chain() -> None:
    robot = erd_robot("ur5")
    assert robot.joint_names == (
        "shoulder_pan_joint",
        "shoulder_lift_joint",
        "elbow_joint",
        "wrist_1_joint",
        "wrist_2_joint",
        "wrist_3_joint",
    )


@needs_erd
def test_kinova_continuous_joints_take_any_angle() -> None:
    robot = erd_robot("kinova")
    assert [j.continuous for j in robot.joints] == [True, False, False, True, False, True]
    q = [3 * math.pi, 2.0, 2.0, -5 * math.pi / 2, 1.0, 7.0]
    wrapped = [math.remainder(v, 2 * math.pi) for v in q]
    np.testing.assert_allclose(
        robot.ee_pose(q).homogeneous, robot.ee_pose(wrapped).homogeneous, atol=1e-12
    )


@needs_erd
def test_robot_flag_finds_example_robots() -> None:
    ini = find_ini(None)
    settings = load_settings(ini, {"robot": "ur5"})
    assert settings.urdf == example_robots()["ur5"].urdf
    assert (settings.base, settings.eelink) == ("base_link", "tool0")
    with pytest.raises(ConfigError, match="unknown robot 'ur55'") as caught:
        load_settings(ini, {"robot": "ur55"})
    assert "panda" in caught.value.choices and "motoman_sia20d" in caught.value.choices


@needs_erd
def test_list_robots(capsys: pytest.CaptureFixture[str]) -> None:
    assert cli.main(["--list-robots"]) == 0
    out = capsys.readouterr().out
    assert "motoman_sia20d" in out and "cmdinterpreter.ini" in out
    panda = next(line for line in out.splitlines() if line.startswith("panda "))
    assert "panda_link0 -> panda_hand_tcp" in panda and "example-robot-data" in panda


def test_without_example_robot_data(monkeypatch: pytest.MonkeyPatch) -> None:
    from c2rviz.robot import catalogue

    monkeypatch.setattr(catalogue, "example_robot_data_dir", lambda: None)
    monkeypatch.setattr(catalogue, "example_robots", dict)
    with pytest.raises(ConfigError, match="not installed: pip install example-robot-data"):
        catalogue.find_robot("ur5")
    assert "pip install example-robot-data" in catalogue.listing([])


# --- a tree: prismatic lift, continuous wrist, mimic finger, a branch off the chain -----


@pytest.fixture(scope="module")
def tree() -> Robot:
    return Robot.from_urdf(TREE, "base_link", "tool0")


def test_tree_needs_an_end_link() -> None:
    with pytest.raises(RobotError, match="name the end-effector link") as caught:
        Robot.from_urdf(TREE)
    for leaf in ("tool0", "finger_left", "finger_right", "camera"):
        assert leaf in str(caught.value)


def test_tree_chain(tree: Robot) -> None:
    assert tree.joint_names == ("lift", "shoulder", "elbow", "wrist")
    assert list(tree.joint_names) == pinocchio_chain(tree.model, "base_link", "tool0")
    assert tree.prismatic == (True, False, False, False)
    assert (tree.lower[0], tree.upper[0]) == (0.0, 0.5)
    assert tree.joints[3].continuous
    np.testing.assert_allclose(
        tree.ee_pose([0.2, 0, 0, 0]).translation, [0.65, 0, 0.35], atol=1e-12
    )


def test_off_chain_joints_stay_neutral_and_mimic_follows() -> None:
    """Every link where yourdfpy puts it: off-chain joints neutral, the mimic finger following."""
    robot = Robot.from_urdf(TREE, "base_link", "finger_left")
    assert robot.joint_names == ("lift", "shoulder", "elbow", "wrist", "finger_left_joint")
    urdf = yourdfpy.URDF.load(str(TREE), load_meshes=False, build_scene_graph=True)
    model, data = robot.model, robot.model.createData()
    rng = np.random.default_rng(7)
    for _ in range(5):
        full = robot.configuration(robot.random(rng))
        pin.framesForwardKinematics(model, data, full)
        cfg = []
        for name in urdf.actuated_joint_names:
            jm = model.joints[model.getJointId(name)]
            value = full[jm.idx_q : jm.idx_q + jm.nq]
            cfg.append(math.atan2(value[1], value[0]) if jm.nq == 2 else value[0])
        urdf.update_cfg(np.array(cfg))
        for link in urdf.link_map:
            expected = urdf.get_transform(link, "base_link")
            got = data.oMf[model.getFrameId(link, pin.BODY)].homogeneous
            np.testing.assert_allclose(got, expected, atol=1e-9, err_msg=link)
    camera_pan = model.joints[model.getJointId("camera_pan")]
    assert robot.neutral[camera_pan.idx_q] == 0.5  # 0 is outside 0.5..1.0: nearest limit


# --- a package whose mesh folder is missing ------------------------------------------


def test_missing_mesh_folder_loads_with_a_warning(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    package = tmp_path / "tiny_description"
    shutil.copytree(TINY_PACKAGE, package, ignore=shutil.ignore_patterns("meshes"))
    robot = Robot.from_urdf(package / "urdf" / "tiny.urdf")  # kinematics need no meshes
    assert robot.joint_names == ("joint1", "joint2")
    missing = {m.uri: m for m in robot.source.missing_meshes()}
    link_uri = "package://tiny_description/meshes/link.stl"
    assert missing[link_uri].links == ("base_link", "link1")
    assert package / "meshes" / "link.stl" in missing[link_uri].searched
    visuals = pytest.importorskip("c2rviz.robot.visuals")
    with caplog.at_level(logging.WARNING, logger="c2rviz"):
        geometry = visuals.load_link_geometry(robot.source)
    text = caplog.text
    assert link_uri in text and str(package / "meshes" / "link.stl") in text
    assert all(geometry[link].visual for link in ("base_link", "link1", "link2"))


# --- prismatic joints over a real socket ---------------------------------------------


@pytest.fixture
def tree_server(tree: Robot) -> Iterator[ServerThread]:
    server = ServerThread(tree, ServerLimits()).start()
    yield server
    server.stop()


@pytest.fixture
def client(tree_server: ServerThread) -> Iterator[Client]:
    client = Client(tree_server.host, tree_server.port)
    yield client
    client.close()


@pytest.mark.parametrize("mode", ["degrees", "radians"])
def test_prismatic_joint_takes_metres_in_every_mode(client: Client, mode: str) -> None:
    assert client.ask(mode) == "ok"
    angle = 90 if mode == "degrees" else math.pi / 2
    assert client.ask(f"joints 0.25,0,{angle:.12g},0") == "ok"
    where = [float(v) for v in client.ask("where").removeprefix("ok ").split(",")]
    assert where == pytest.approx([0.25, 0, angle, 0])
    x, y, z = (float(v) for v in client.ask("pose").removeprefix("ok ").split(",")[:3])
    # elbow at x 0.3, z 0.05 + 0.25 + 0.1 = 0.4 m; forearm and tool (0.35 m) point down
    assert (x, y, z) == pytest.approx((0.3, 0, 0.4 - 0.35), abs=1e-9)
    reply = client.ask("move 0 30")
    assert reply.startswith("error: lift (index 0) = 30 m is outside its limits 0..0.5 m")
    assert client.ask("limits").startswith("ok 0..0.5 m,")  # the lift says metres
    wrist = "-57295779.51..57295779.51 deg" if mode == "degrees" else "-1000000..1000000 rad"
    assert client.ask("limits").endswith(f",{wrist}")  # the wrist is continuous: +-1e6 rad


def test_continuous_joint_takes_any_angle(client: Client, tree_server: ServerThread) -> None:
    assert client.ask("degrees") == "ok"
    assert client.ask("move 3 720") == "ok"
    assert client.ask("where") == "ok 0,0,0,720"
    assert tree_server.q[3] == pytest.approx(4 * math.pi)


# --- limits that print badly: puma560's +-1.570796325 rad, the seed's +-3.1416 rad ---------


@pytest.fixture
def limits_client() -> Iterator[Client]:
    server = ServerThread(Robot.from_urdf(LIMITS_URDF), ServerLimits()).start()
    client = Client(server.host, server.port)
    yield client
    client.close()
    server.stop()


def test_a_limit_prints_one_way_in_limits_and_errors(limits_client: Client) -> None:
    client = limits_client
    assert client.ask("degrees") == "ok"
    low, high = client.ask("limits").removeprefix("ok ").split(",")[0].split(" ")[0].split("..")
    assert (low, high) == ("-89.9999999", "89.9999999")
    assert client.ask("move 0 89.99999999") == (
        "error: joint1 (index 0) = 89.99999999 deg is outside its limits "
        "-89.9999999..89.9999999 deg"
    )
    assert client.ask("move 0 89.9999999") == "ok"  # the printed limit is accepted
    assert client.ask("radians") == "ok"
    assert client.ask("move 1 3.1416000032") == (
        "error: joint2 (index 1) = 3.141600003 rad is outside its limits -3.1416..3.1416 rad"
    )


@pytest.mark.parametrize(
    ("mode", "edge"), [("degrees", "57295779.51"), ("radians", "1000000")], ids=["deg", "rad"]
)
def test_a_continuous_joint_is_bounded_so_where_is_always_accepted(
    limits_client: Client, mode: str, edge: str
) -> None:
    """+-CONTINUOUS_LIMIT (1e6 rad), refused past it like any limit; every reply finite."""
    client = limits_client
    unit = "deg" if mode == "degrees" else "rad"
    assert client.ask(mode) == "ok"
    assert client.ask("move 2 1.7e308") == (
        f"error: joint3 (index 2) = 1.7e+308 {unit} is outside its limits -{edge}..{edge} {unit}"
    )
    assert client.ask("move 2 -1.7976931348623157e308").startswith(
        "error: joint3 (index 2) = -1.797693135e+308"
    )
    for value in (edge, f"-{edge}", "123456.789012345", "720"):
        assert client.ask(f"move 2 {value}") == "ok"
        where = client.ask("where")
        assert all(math.isfinite(float(v)) for v in where.removeprefix("ok ").split(","))
        assert client.ask("joints " + where.removeprefix("ok ")) == "ok"  # sent back
        assert client.ask("where") == where


def test_motion_keeps_a_continuous_joint_within_the_same_bound(limits_client: Client) -> None:
    """The planner takes the robot's limits, so it goes where the session lets it."""
    robot = Robot.from_urdf(LIMITS_URDF)
    limits = motion_limits(robot)
    assert (limits.lower[2], limits.upper[2]) == (-CONTINUOUS_LIMIT, CONTINUOUS_LIMIT)
    client = limits_client
    assert client.ask("joints 0,0,999999.9") == "ok"
    assert client.ask("motion on") == "ok"
    # A rounding error past the limit counts as at it, for the session and the planner.
    assert client.ask("move 2 1000000.0005") == "ok"  # on arrival
    assert client.ask("where") == "ok 0,0,1000000"


def test_ini_section_with_package_path_and_xacro_args(tmp_path: Path) -> None:
    ini = tmp_path / "cmdinterpreter.ini"
    xacro_file = TINY_PACKAGE / "urdf" / "tiny.urdf.xacro"
    ini.write_text(
        f"[tiny]\nurdf = {xacro_file}\npackage_path = {DATA / 'tiny_ws'}\n"
        "xacro_args = length:=0.4 prefix:=r_\n"
    )
    settings = load_settings(ini, {"robot": "tiny", "xacro_args": ["prefix:=l_"]})
    assert settings.package_paths == ((DATA / "tiny_ws").resolve(),)
    assert settings.xacro_args == ("length:=0.4", "prefix:=r_", "prefix:=l_")  # flags last
    robot = Robot.from_urdf(
        settings.urdf,  # type: ignore[arg-type]
        package_paths=settings.package_paths,
        xacro_args=settings.xacro_args,
    )
    assert robot.joint_names == ("l_joint1", "l_joint2")
    assert robot.ee_pose([0, 0]).translation[2] == pytest.approx(0.5)


# --- the whole program: a user's xacro package in one command ------------------------


def test_one_command_runs_a_xacro_package(c2rviz_process: Callable[..., object]) -> None:
    xacro_file = TINY_PACKAGE / "urdf" / "tiny.urdf.xacro"
    proc = c2rviz_process("--urdf", str(xacro_file), "--xacro-arg", "length:=0.5", "--no-viewer")
    client = Client("127.0.0.1", proc.port)  # type: ignore[attr-defined]
    try:
        assert client.ask("names") == "ok tiny_xacro joint1,joint2"
        assert client.ask("pose") == "ok 0,0,0.6,0,0,0"
        assert client.ask("quit").startswith("ok")
    finally:
        client.close()
    assert proc.wait() == 0  # type: ignore[attr-defined]
