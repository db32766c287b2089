"""Finding a robot's description and meshes without ROS: package://, xacro, search order."""

from __future__ import annotations

import os
import shutil
import warnings
from pathlib import Path

import numpy as np
import pytest
import trimesh
from support import ROOT
from xacro import substitution_args

from c2rviz.app.cli import main
from c2rviz.errors import ConfigError, RobotError
from c2rviz.robot.model import Robot
from c2rviz.robot.sources import RobotSource, load_source, parse_xacro_args, split_package_path

DATA = ROOT / "tests" / "data"
WS_SRC = DATA / "tiny_ws" / "src"
TINY = WS_SRC / "tiny_description" / "urdf" / "tiny.urdf"
TINY_XACRO = WS_SRC / "tiny_description" / "urdf" / "tiny.urdf.xacro"
LINK_STL = WS_SRC / "tiny_description" / "meshes" / "link.stl"
FINGER_URI = "package://tiny_gripper/meshes/finger.stl"
FINGER_STL = WS_SRC / "gripper-checkout" / "meshes" / "finger.stl"
NO_ENV: dict[str, str] = {}  # no ROS_PACKAGE_PATH / AMENT_PREFIX_PATH from the test machine


def test_fixture_meshes_load_cleanly() -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        mesh = trimesh.load(LINK_STL, force="mesh")
    assert len(mesh.faces) == 4 and mesh.is_watertight


def test_package_found_upward_by_folder_name() -> None:
    source = load_source(TINY, environ=NO_ENV)
    assert source.resolve("package://tiny_description/meshes/link.stl") == LINK_STL.resolve()


def test_package_named_only_in_package_xml_is_missing_without_a_path() -> None:
    source = load_source(TINY, environ=NO_ENV)
    assert source.resolve(FINGER_URI) is None
    [missing] = source.missing_meshes()
    assert missing.uri == FINGER_URI and missing.links == ("link2",)
    message = missing.message()
    assert FINGER_URI in message and "--package-path" in message
    # every place searched is named: each folder above the URDF, as <folder>/tiny_gripper/...
    for folder in [TINY.parent.resolve(), *TINY.parent.resolve().parents]:
        assert str(folder / "tiny_gripper" / "meshes" / "finger.stl") in message


@pytest.mark.parametrize(
    "package_path",
    [
        WS_SRC,
        WS_SRC.parent,
        WS_SRC / "gripper-checkout",
        f"tiny_gripper={FINGER_STL.parent.parent}",
    ],
    ids=["workspace-src", "workspace", "the-package-itself", "name=dir"],
)
def test_package_path_flag(package_path: str | Path) -> None:
    source = load_source(TINY, [package_path], environ=NO_ENV)
    assert source.resolve(FINGER_URI) == FINGER_STL.resolve()
    assert source.missing_meshes() == []


def test_ros_package_path() -> None:
    source = load_source(TINY, environ={"ROS_PACKAGE_PATH": f"/nonexistent:{WS_SRC.parent}"})
    assert source.resolve(FINGER_URI) == FINGER_STL.resolve()


def test_ament_prefix_path(tmp_path: Path) -> None:
    shutil.copytree(FINGER_STL.parent.parent, tmp_path / "share" / "tiny_gripper")
    source = load_source(TINY, environ={"AMENT_PREFIX_PATH": str(tmp_path)})
    assert source.resolve(FINGER_URI) == tmp_path / "share/tiny_gripper/meshes/finger.stl"


def test_search_order_flag_then_env_then_upward(tmp_path: Path) -> None:
    """The same package in three places: --package-path wins, then ROS_PACKAGE_PATH."""
    urdf_dir = tmp_path / "tiny_description" / "urdf"
    shutil.copytree(TINY.parent.parent, tmp_path / "tiny_description")
    for where in ("flag", "env"):
        shutil.copytree(TINY.parent.parent, tmp_path / where / "tiny_description")
    uri = "package://tiny_description/meshes/link.stl"
    env = {"ROS_PACKAGE_PATH": str(tmp_path / "env")}
    by_flag = load_source(urdf_dir / "tiny.urdf", [tmp_path / "flag"], environ=env)
    assert by_flag.resolve(uri) == tmp_path / "flag/tiny_description/meshes/link.stl"
    by_env = load_source(urdf_dir / "tiny.urdf", environ=env)
    assert by_env.resolve(uri) == tmp_path / "env/tiny_description/meshes/link.stl"
    upward = load_source(urdf_dir / "tiny.urdf", environ=NO_ENV)
    assert upward.resolve(uri) == tmp_path / "tiny_description/meshes/link.stl"
    searched = by_flag.searched(uri)
    assert searched.index(tmp_path / "flag/tiny_description/meshes/link.stl") < searched.index(
        tmp_path / "env/tiny_description/meshes/link.stl"
    )


def test_scan_skips_ignored_folders(tmp_path: Path) -> None:
    shutil.copytree(FINGER_STL.parent.parent, tmp_path / "ignored" / "gripper")
    (tmp_path / "ignored" / "CATKIN_IGNORE").touch()
    assert load_source(TINY, [tmp_path], environ=NO_ENV).resolve(FINGER_URI) is None


def test_relative_file_and_remote_uris(tmp_path: Path) -> None:
    tree = load_source(DATA / "tree_robot" / "tree.urdf", environ=NO_ENV)
    assert tree.resolve("meshes/hand.stl") == (DATA / "tree_robot/meshes/hand.stl").resolve()
    spaced = tmp_path / "a folder" / "m.stl"
    spaced.parent.mkdir()
    shutil.copy(LINK_STL, spaced)
    assert tree.resolve("file://" + str(spaced).replace(" ", "%20")) == spaced
    assert tree.resolve(str(spaced)) == spaced
    assert tree.resolve("https://example.com/m.stl") is None
    assert tree.searched("https://example.com/m.stl") == []


def test_missing_package_path_is_a_config_error(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match="is not a folder"):
        load_source(TINY, [tmp_path / "nope"], environ=NO_ENV)


def test_a_missing_name_dir_names_the_package(tmp_path: Path) -> None:
    nope = tmp_path / "nope"
    message = f"--package-path {str(nope)!r} (for package tiny_gripper) is not a folder"
    with pytest.raises(ConfigError) as info:
        load_source(TINY, [f"tiny_gripper={nope}"], environ=NO_ENV)
    assert str(info.value) == message


def test_split_package_path_forms(tmp_path: Path) -> None:
    odd = tmp_path / "a=b"  # a folder whose own name holds '=' is a DIR
    odd.mkdir()
    assert split_package_path("a=b", tmp_path) == (None, odd)
    assert split_package_path("pkg=x/y", tmp_path) == ("pkg", tmp_path / "x" / "y")
    assert split_package_path("x/y", tmp_path) == (None, tmp_path / "x" / "y")
    assert split_package_path(f"pkg={tmp_path}", Path("/elsewhere")) == ("pkg", tmp_path)
    assert split_package_path("~/ws")[1] == Path.home() / "ws"


def test_mesh_uris_survive_xml_that_elementtree_rejects() -> None:
    source = RobotSource('<robot name="x"><!-- a -- b --><link name="l"><visual><geometry>'
                         '<mesh filename="m.stl"/></geometry></visual></link></robot>')  # fmt: skip
    assert list(source.mesh_uris()) == ["m.stl"]


def test_xacro_expands_with_arguments() -> None:
    source = load_source(TINY_XACRO, (), ["length:=0.5", "prefix:=left_"], environ=NO_ENV)
    robot = Robot.from_source(source)
    assert robot.name == "tiny_xacro"
    assert robot.joint_names == ("left_joint1", "left_joint2")
    assert (robot.base, robot.eelink) == ("left_base_link", "left_link2")
    np.testing.assert_allclose(robot.ee_pose([0.0, 0.0]).translation, [0, 0, 0.6], atol=1e-12)
    # $(find tiny_description) was answered without ROS: the mesh is a file:// path that exists
    assert source.missing_meshes() == []
    assert f"file://{LINK_STL.parent.parent.resolve()}/meshes/link.stl" in source.xml
    assert substitution_args._eval_find.__module__ == "xacro.substitution_args"  # restored


def test_xacro_missing_argument_says_how_to_give_it() -> None:
    with pytest.raises(RobotError, match=r"length.*--xacro-arg name:=value"):
        load_source(TINY_XACRO, environ=NO_ENV)


@pytest.mark.parametrize(
    "body",
    [
        '<link name="a"><visual><geometry><mesh filename="$(find no_such_pkg)/m.stl"/>'
        "</geometry></visual></link>",
        '<xacro:include filename="$(find no_such_pkg)/urdf/arm.xacro"/><link name="a"/>',
    ],
    ids=["in-an-attribute", "in-an-include"],
)
def test_xacro_unknown_package_is_one_sentence(tmp_path: Path, body: str) -> None:
    path = tmp_path / "r.xacro"
    path.write_text(f'<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">{body}</robot>')
    with pytest.raises(RobotError) as info:
        load_source(path, environ=NO_ENV)
    assert str(info.value) == (
        f"cannot expand {path}: package 'no_such_pkg' not found in --package-path, "
        f"ROS_PACKAGE_PATH, AMENT_PREFIX_PATH or the folders above {tmp_path} "
        "(give the folder that holds it with --package-path DIR or NAME=DIR)"
    )


@pytest.mark.parametrize("arg", ["length", ":=1", "length=1"])
def test_bad_xacro_argument(arg: str) -> None:
    with pytest.raises(ConfigError, match="is not name:=value"):
        parse_xacro_args([arg])


def test_xacro_arguments_for_a_plain_urdf_are_refused() -> None:
    with pytest.raises(ConfigError, match="not a .xacro file"):
        load_source(TINY, (), ["length:=1"], environ=NO_ENV)


SDF = """<?xml version="1.0"?>
<!-- a model as Gazebo describes it -->
<sdf version="1.7"><model name="arm"><link name="base"/></model></sdf>
"""


@pytest.mark.parametrize(
    ("name", "text", "problem"),
    [
        ("arm.sdf", SDF, "its root element is <sdf>, not <robot> (an SDF file: c2rviz reads "
         "URDF and xacro)"),
        ("scene.xml", "<mujoco model='arm'/>", "its root element is <mujoco>, not <robot>"),
        ("arm.urdf", "solid arm\nendsolid arm\n", "it is not XML (a URDF starts with <robot ...>)"),
    ],
    ids=["sdf", "mjcf", "not-xml"],
)  # fmt: skip
def test_a_file_that_is_not_a_urdf_gets_only_our_message(tmp_path, capfd, name, text, problem):
    path = tmp_path / name
    path.write_text(text)
    with pytest.raises(RobotError) as info:
        Robot.from_urdf(path)
    assert str(info.value) == f"{path} is not a URDF: {problem}"
    assert main(["--urdf", str(path), "--no-viewer"]) == 2
    out, err = capfd.readouterr()  # fd 1 and 2: what urdfdom would print goes there
    assert (out, err) == ("", f"c2rviz: {path} is not a URDF: {problem}\n")


def test_a_urdf_with_a_declaration_comments_and_a_doctype_is_a_urdf(tmp_path, capfd):
    path = tmp_path / "r.urdf"
    path.write_text(
        '\ufeff<?xml version="1.0"?>\n<!-- a -- b -->\n<!DOCTYPE robot>\n'
        '<robot name="r"><link name="a"/><link name="b"/><joint name="j" type="revolute">'
        '<parent link="a"/><child link="b"/><limit lower="-1" upper="1" effort="1" '
        'velocity="1"/></joint></robot>',
        encoding="utf-8",
    )
    assert Robot.from_urdf(path).joint_names == ("j",)


def snake(joints: int) -> str:
    """A URDF chain of ``joints`` revolute joints."""
    links = "".join(f'<link name="l{i}"/>' for i in range(joints + 1))
    chain = "".join(
        f'<joint name="j{i}" type="revolute"><parent link="l{i - 1}"/><child link="l{i}"/>'
        '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>'
        for i in range(1, joints + 1)
    )
    return f'<?xml version="1.0"?><robot name="snake">{links}{chain}</robot>'


def test_a_robot_past_the_size_limits_is_refused_before_any_model(tmp_path):
    """Issue 23.7: 500 joints took 7 GB and never started; past MAX_JOINTS (or MAX_LINKS, or
    MAX_MESH_BYTES of meshes) the robot is refused in one sentence."""
    from c2rviz.robot.sources import MAX_JOINTS, MAX_LINKS, MAX_MESH_BYTES

    ok = tmp_path / "ok.urdf"
    ok.write_text(snake(MAX_JOINTS))
    assert Robot.from_urdf(ok).n == MAX_JOINTS
    big = tmp_path / "big.urdf"
    big.write_text(snake(500))
    with pytest.raises(RobotError, match=rf"big.urdf has 501 links, over the limit of {MAX_LINKS}"):
        load_source(big)
    heavy = tmp_path / "heavy.urdf"
    (tmp_path / "huge.stl").write_bytes(b"\0" * 1024)
    os.truncate(tmp_path / "huge.stl", MAX_MESH_BYTES + 1)  # sparse: no disk is used
    heavy.write_text(
        '<robot name="h"><link name="a"><visual><geometry><mesh filename="huge.stl"/>'
        "</geometry></visual></link></robot>"
    )
    with pytest.raises(
        RobotError, match=r"names 268,435,457 bytes of mesh files, over the limit of 268,435,456"
    ):
        load_source(heavy)


def test_a_cyclic_urdf_names_the_cycle(tmp_path):
    """Issue 23.10: urdfdom says only "no root link"; we name the cycle, or the link with
    two parents."""
    limit = '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/>'

    def joint(name: str, above: str, below: str) -> str:
        parent, child = f'<parent link="{above}"/>', f'<child link="{below}"/>'
        return f'<joint name="{name}" type="revolute">{parent}{child}{limit}</joint>'

    links = '<link name="a"/><link name="b"/><link name="c"/>'
    cyclic = tmp_path / "cyc.urdf"
    cyclic.write_text(
        f'<robot name="c">{links}{joint("j1", "a", "b")}{joint("j2", "b", "c")}'
        f"{joint('j3', 'c', 'a')}</robot>"
    )
    with pytest.raises(RobotError, match=r"not a tree of links: its joints form a cycle: link"):
        load_source(cyclic)
    twice = tmp_path / "twice.urdf"
    twice.write_text(
        f'<robot name="t">{links}{joint("j1", "a", "c")}{joint("j2", "b", "c")}</robot>'
    )
    with pytest.raises(RobotError, match=r"link 'c' is the child of two joints \('j1' and 'j2'\)"):
        load_source(twice)


def test_a_vanishing_velocity_limit_is_refused_at_start(tmp_path, capsys):
    """Issue 23.10: velocity="1e-300" passed as > 0 and broke the first move in ruckig."""
    urdf = tmp_path / "slow.urdf"
    urdf.write_text(snake(2).replace('velocity="1"', 'velocity="1e-300"', 1))
    assert main(["--urdf", str(urdf), "--no-viewer", "--port", "0"]) == 2
    err = capsys.readouterr().err
    assert "j1's URDF velocity limit 1e-300 is below 1e-06" in err and err.count("\n") == 1, err
