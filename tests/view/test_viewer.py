"""The viser scene: link poses from Pinocchio, coalesced sends, the panel, safety.

Each test runs a real ``ViserScene`` on a free port, bound to a real ``World``
on an asyncio loop driven from the test's thread (the loop only runs inside
``run``, like the program's loop between commands). Page input comes over a
real websocket (``viewer_tabs.Tab``), as a page sends it.
"""

from __future__ import annotations

import io
import logging
import socket
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin
import pytest
import trimesh
import yourdfpy
from support import ROBOTS, ROOT, load_robot
from viewer_tabs import Harness

from c2rviz.robot.mesh_files import Mesh
from c2rviz.robot.model import Robot
from c2rviz.robot.visuals import load_link_geometry
from c2rviz.session import Services
from c2rviz.view import adapter
from c2rviz.view.viser_scene import RECENT_COMMANDS, ViserScene
from c2rviz.world.observer import Marker
from c2rviz.world.world import World


@pytest.fixture
def harness() -> Iterator[Callable[..., Harness]]:
    made: list[Harness] = []

    def make(robot: str | Robot = "motoman_sia20d", **kwargs: Any) -> Harness:
        chosen = load_robot(robot) if isinstance(robot, str) else robot
        h = Harness(World(chosen), rng=np.random.default_rng(7), **kwargs)
        made.append(h)
        return h

    yield make
    for h in made:
        h.close()


def fk(robot: Robot, q: Any) -> pin.Data:
    """Independent Pinocchio FK: every frame's placement for chain values ``q``."""
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, robot.configuration(q))
    return data


def assert_frames_match(h: Harness, q: Any, tol: float = 1e-9) -> None:
    data = fk(h.robot, q)
    view = h.scene.views[h.world.default]
    for link in h.scene.link_frames:
        expected = data.oMf[h.robot.model.getFrameId(link, pin.BODY)]
        got = view.link_pose(link)  # composed down the nested link frames
        np.testing.assert_allclose(got.translation, expected.translation, atol=tol, err_msg=link)
        np.testing.assert_allclose(got.rotation, expected.rotation, atol=tol, err_msg=link)


@pytest.mark.parametrize("name", list(ROBOTS))
def test_link_frames_are_pinocchio_fk(harness: Callable[..., Harness], name: str) -> None:
    h = harness(name, hz=1000.0)
    rng = np.random.default_rng(1)
    assert set(h.scene.link_frames) == set(h.robot.link_names())
    for _ in range(30):
        q = h.robot.random(rng)
        h.call(lambda q=q: h.world.set_q(q))
        h.until(lambda q=q: h.scene.sent_q == tuple(q), "the send of the new pose")
        assert_frames_match(h, q)


@pytest.mark.parametrize("name", list(ROBOTS))
def test_urdf_link_frames_are_pinocchio_body_frames(name: str) -> None:
    """The viewer hangs URDF geometry on Pinocchio's body frames: they must be the
    URDF's link frames. yourdfpy's own FK agrees with Pinocchio within 1e-6 m."""
    robot = load_robot(name)
    model = robot.model
    urdf = yourdfpy.URDF.load(io.BytesIO(robot.source.xml.encode()), load_meshes=False)
    root = urdf.base_link
    rng = np.random.default_rng(2)
    for _ in range(100):
        full = robot.configuration(robot.random(rng))
        cfg = {}
        for j in range(1, model.njoints):
            jm = model.joints[j]
            if jm.nq == 1:
                cfg[model.names[j]] = float(full[jm.idx_q])
            elif jm.nq == 2:
                cfg[model.names[j]] = float(np.arctan2(full[jm.idx_q + 1], full[jm.idx_q]))
        urdf.update_cfg({k: v for k, v in cfg.items() if k in urdf.actuated_joint_names})
        data = robot.model.createData()
        pin.framesForwardKinematics(model, data, full)
        for link in robot.link_names():
            expected = data.oMf[model.getFrameId(link, pin.BODY)].homogeneous
            got = urdf.get_transform(link, root)
            np.testing.assert_allclose(got, expected, atol=1e-6, err_msg=link)


def test_the_fingers_are_drawn_at_the_gripper_opening(harness: Callable[..., Harness]) -> None:
    h = harness("fanuc_lrmate200id", hz=1000.0)
    robot = h.robot
    view = h.scene.views[h.world.default]
    for opening in (1.0, 0.25):
        h.call(lambda o=opening: h.world.grips.set(h.world.state(), o, "test"))
        data = robot.model.createData()
        pin.framesForwardKinematics(robot.model, data, robot.configuration(robot.home, opening))
        for link in ("gripper_finger_left", "gripper_finger_right"):
            expected = data.oMf[robot.model.getFrameId(link, pin.BODY)].translation
            h.until(  # the send after the change (no other change moves a finger)
                lambda link=link, expected=expected: np.allclose(
                    view.link_pose(link).translation, expected, atol=1e-9
                ),
                f"{link} drawn at opening {opening}",
            )
    left, right = (view.link_pose(f"gripper_finger_{s}").translation for s in ("left", "right"))
    assert np.linalg.norm(left - right) == pytest.approx(0.002 + 0.25 * 0.06)


def test_a_flood_is_coalesced_and_the_last_pose_wins(harness: Callable[..., Harness]) -> None:
    h = harness(hz=100.0)
    h.run(0.05)
    before = h.scene.sends
    rng = np.random.default_rng(3)
    poses = [h.robot.random(rng) for _ in range(10_000)]

    def flood() -> None:
        for q in poses:
            h.world.set_q(q)

    h.call(flood)
    h.run(0.1)
    assert 1 <= h.scene.sends - before <= 3
    assert h.scene.sent_q == tuple(poses[-1])
    assert_frames_match(h, poses[-1])


def test_a_lone_command_is_sent_at_once(harness: Callable[..., Harness]) -> None:
    h = harness(hz=10.0)  # a long period: waiting for it would show
    h.run(0.15)
    before = h.scene.sends
    q = h.robot.random(np.random.default_rng(4))
    h.call(lambda: h.world.set_q(q))
    h.run(0.0)  # one pass of the loop, far less than the 0.1 s period
    assert h.scene.sends == before + 1
    assert h.scene.sent_q == tuple(q)
    # A second command within the period waits for the period, then goes out.
    q2 = h.robot.random(np.random.default_rng(5))
    h.call(lambda: h.world.set_q(q2))
    h.run(0.0)
    assert h.scene.sent_q == tuple(q)
    h.run(0.15)
    assert h.scene.sent_q == tuple(q2)


def test_sliders_follow_the_world_without_commanding_it(
    harness: Callable[..., Harness], monkeypatch: pytest.MonkeyPatch
) -> None:
    h = harness()
    set_q_calls: list[tuple[float, ...]] = []
    original = h.world.set_q
    monkeypatch.setattr(
        h.world, "set_q", lambda q, *args: (set_q_calls.append(tuple(q)), original(q, *args))
    )
    tab = h.tab()
    q = [0.5, -0.3, 1.0, 0.2, -1.5, 0.7, 2.0]
    h.call(lambda: h.world.set_q(q))
    h.run(0.1)
    sliders = h.panel.sliders
    assert [s.value for s in sliders] == pytest.approx(np.degrees(q).tolist())
    assert [s.label for s in sliders] == list(h.robot.joint_names)
    tab.wait(lambda: tab.values(sliders[4]) != [], "the tab to be sent the sliders")
    assert tab.values(sliders[4])[-1] == pytest.approx(np.degrees(-1.5))
    h.run(0.1)
    assert set_q_calls == [tuple(q)]  # the programmatic slider updates did not re-command


def test_a_slider_from_the_page_commands_the_world_through_the_session(
    harness: Callable[..., Harness],
) -> None:
    h = harness()
    tab, other = h.tab(), h.tab()
    slider = h.panel.sliders[1]
    tab.set(slider, 30.0)
    h.until(lambda: h.world.q[1] == pytest.approx(np.radians(30.0)), "the page's move")
    assert ("move 1 30.0", True) in h.scene._commands  # through the page's session
    other.wait(lambda: 30.0 in other.values(slider), "the other tab to see the value")
    tab.set(slider, 500.0)  # beyond joint_l's 1.91 rad: refused
    h.until(lambda: h.scene.page_input.refused == 1, "the refusal")
    assert h.world.q[1] == pytest.approx(np.radians(30.0))
    assert h.world.q[0] == 0.0
    tab.wait(lambda: tab.values(slider)[-1:] == [30.0], "the true value back")


@pytest.mark.parametrize("bad", [500.0, float("nan"), "ninety"], ids=["over", "nan", "text"])
def test_a_bad_slider_value_over_the_websocket_changes_nothing_and_snaps_back(
    harness: Callable[..., Harness], bad: object
) -> None:
    """The page is a source like any other: its value goes through the session's checks
    (a NaN or a word does not even get past the door); a refused one leaves the world as
    it was and the slider shows the true value again."""
    h = harness()
    h.call(lambda: h.world.set_q([0.0, 0.5, 0, 0, 0, 0, 0]))
    h.run(0.05)
    before = h.world.q
    slider = h.panel.sliders[1]
    door = adapter.door(h.scene.server)
    tab = h.tab()
    told = len(tab.values(slider))
    tab.set(slider, bad)
    h.until(
        lambda: h.scene.page_input.refused + door.refused["input"] == 1,
        "the page's value to be refused",
    )
    h.run(0.05)
    assert h.world.q == before
    assert slider.value == pytest.approx(np.degrees(0.5))
    if isinstance(bad, float) and bad == 500.0:  # the session refused it
        assert ("move 1 500.0", False) in h.scene._commands
    # Refused by the session or dropped at the door: the tab is sent the true value.
    h.until(lambda: len(tab.values(slider)) > told, "the true value back")
    assert tab.values(slider)[-1] == slider.value
    where = h.call(lambda: h.scene.sessions[h.world.default].run("where"))
    assert [float(v) for v in where.removeprefix("ok ").split(",")] == pytest.approx(
        np.degrees(before).tolist()
    )


def test_the_buttons_and_the_collision_checkbox(harness: Callable[..., Harness]) -> None:
    h = harness()
    tab, other = h.tab(), h.tab()
    buttons = h.panel.buttons
    tab.set(buttons["rand"], True)
    h.until(lambda: h.world.q != h.robot.home, "Random")
    tab.set(buttons["home"], True)
    h.until(lambda: h.world.q == h.robot.home, "Home")
    nodes = h.scene.server.scene._handle_from_node_name
    collisions = [n for n in nodes if "/collision_" in n]
    assert collisions and not any(nodes[n].visible for n in collisions)
    checkbox = h.scene.state_panel.collision
    tab.set(checkbox, True)
    h.until(lambda: all(nodes[n].visible for n in collisions), "the collision geometry")
    other.wait(lambda: other.values(checkbox) == [True], "the other tab's checkbox")
    assert checkbox.value is True


def drawn_markers(h: Harness) -> dict[str, np.ndarray]:
    """The positions of the markers drawn, by shape (what every tab is sent)."""
    return {
        shape: np.asarray(node.batched_positions) if node.visible else np.zeros((0, 3))
        for (_, shape), node in h.scene.markers.nodes.items()
    }


def test_markers_are_drawn_and_cleared(harness: Callable[..., Harness]) -> None:
    h = harness()
    tab = h.tab()
    shapes = ("sphere", "cube", "arrow", "cylinder")
    for i, shape in enumerate(shapes):
        h.call(
            lambda i=i, shape=shape: h.world.add_marker(
                pin.SE3(np.eye(3), np.array([0.1 * i, 0.0, 0.5])), (1.0, 0.0, 0.0), shape
            )
        )
    h.run(0.05)
    drawn = drawn_markers(h)
    assert sum(len(p) for p in drawn.values()) == len(shapes) == h.scene.marker_count
    assert sorted(drawn) == sorted(shapes)
    np.testing.assert_allclose(drawn["cube"], [[0.1, 0.0, 0.5]], atol=1e-6)
    np.testing.assert_allclose(drawn["cylinder"], [[0.3, 0.0, 0.5]], atol=1e-6)
    cube = h.scene.markers.nodes[h.world.default, "cube"]
    assert tuple(cube.batched_colors[0]) == (255, 0, 0)
    tab.wait(
        lambda: len([m for m in tab.received if m["type"] == "BatchedMeshesMessage"]) == 4,
        "the tab to be sent one node per shape",
    )
    h.call(h.world.clear)
    h.run(0.05)
    assert sum(len(p) for p in drawn_markers(h).values()) == 0
    assert h.scene.marker_count == 0
    assert not any(node.visible for node in h.scene.markers.nodes.values())


def test_a_marker_flood_keeps_the_newest(harness: Callable[..., Harness]) -> None:
    h = harness()
    cap = 1000

    def flood() -> None:
        for i in range(cap + 500):
            marker = Marker((float(i), 0.0, 0.0), (1.0, 0.0, 0.0, 0.0), (0.0, 1.0, 0.0), "sphere")
            h.scene.on_marker(h.robot.name, marker)

    h.call(flood)
    h.run(0.05)
    assert h.scene.marker_count == cap
    xs = sorted(drawn_markers(h)["sphere"][:, 0])
    assert xs == list(range(500, cap + 500))  # the newest 1000, each once


def test_the_panel_shows_clients_commands_and_the_pose(harness: Callable[..., Harness]) -> None:
    h = harness()
    lines = [f"joint 0 {i}" for i in range(12)]

    def talk() -> None:
        h.services.count_clients("tcp", 3)
        for line in lines:
            h.world.note("tcp", line, True)
        h.world.note("tcp", "jump 3", False)

    h.call(talk)
    h.run(0.05)
    state = h.scene.state_panel
    assert state.clients.value == "3"
    newest_first = ["jump 3  [rejected]", *lines[::-1]]
    assert state.recent.value.splitlines() == newest_first[:RECENT_COMMANDS]
    assert "z +1.500 m" in h.panel.pose.value  # the motoman's link_t at home
    assert h.panel.motion.value == "idle"


def test_no_share_button_and_a_share_request_is_refused(
    harness: Callable[..., Harness],
    monkeypatch: pytest.MonkeyPatch,
    caplog: pytest.LogCaptureFixture,
) -> None:
    h = harness()
    server = h.scene.server
    themes = [
        m
        for m in server._websock_server._broadcast_buffer.message_from_id.values()
        if type(m).__name__ == "ThemeConfigurationMessage"
    ]
    assert themes and not themes[-1].show_share_button
    opened: list[str] = []
    monkeypatch.setattr(server, "request_share_url", lambda *a, **k: opened.append("tunnel"))
    door = adapter.door(server)
    with caplog.at_level(logging.WARNING, logger="c2rviz.view"):
        tab = h.tab()
        tab.send({"type": "ShareUrlRequest"})
        h.until(lambda: door.refused["share"] == 1, "the share request's refusal")
    time.sleep(0.2)  # the thread pool would have called it by now
    assert opened == []
    assert server._share_tunnel is None
    assert "share-link request" in caplog.text


def _port_is_free(port: int) -> bool:
    with socket.socket() as probe:
        try:
            probe.bind(("127.0.0.1", port))
        except OSError:
            return False
        return True


def test_stop_frees_the_port() -> None:
    scene = ViserScene(Services(World(load_robot())), "127.0.0.1", 0, 100.0)
    port = int(scene.url.rsplit(":", 1)[1])
    assert not _port_is_free(port)
    scene.stop()
    scene.stop()  # twice is harmless
    assert _port_is_free(port)


def test_url_reports_the_port_bound_when_the_asked_one_is_busy(
    caplog: pytest.LogCaptureFixture,
) -> None:
    with socket.socket() as busy:
        busy.bind(("127.0.0.1", 0))
        busy.listen()
        taken = busy.getsockname()[1]
        scene = ViserScene(Services(World(load_robot())), "127.0.0.1", taken, 100.0)
        try:
            bound = int(scene.url.rsplit(":", 1)[1])
            assert scene.url.startswith("http://127.0.0.1:")
            assert bound != taken
            assert f"viewer port {taken} is busy" in caplog.text
        finally:
            scene.stop()


def test_a_host_that_cannot_be_bound_fails_at_once() -> None:
    with pytest.raises(OSError):
        ViserScene(Services(World(load_robot())), "192.0.2.1", 0, 100.0)  # TEST-NET-1: not ours


def test_no_banner_on_stdout(capsys: pytest.CaptureFixture[str]) -> None:
    scene = ViserScene(Services(World(load_robot())), "127.0.0.1", 0, 100.0)
    scene.stop()
    assert capsys.readouterr().out == ""


MESHY_URDF = """<?xml version="1.0"?>
<robot name="meshy">
  <material name="blue"><color rgba="0 0 1 1"/></material>
  <link name="base">
    <visual><geometry><mesh filename="package://nowhere_pkg/meshes/base.stl"/></geometry>
    </visual>
    <collision><geometry><box size="0.2 0.2 0.1"/></geometry></collision>
  </link>
  <joint name="j1" type="revolute">
    <parent link="base"/><child link="arm"/><origin xyz="0 0 0.1"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/>
  </joint>
  <link name="arm">
    <visual><geometry><mesh filename="meshes/arm.stl" scale="2 2 2"/></geometry>
      <material name="blue"/></visual>
  </link>
  <joint name="j2" type="revolute">
    <parent link="arm"/><child link="hand"/><origin xyz="0 0 0.3"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/>
  </joint>
  <link name="hand">
    <visual><geometry><mesh filename="file:///no/such/hand.dae"/></geometry></visual>
  </link>
</robot>
"""


def test_missing_meshes_warn_and_fall_back(
    tmp_path: Path, harness: Callable[..., Harness], caplog: pytest.LogCaptureFixture
) -> None:
    (tmp_path / "meshes").mkdir()
    trimesh.creation.box(extents=(0.05, 0.05, 0.15)).export(tmp_path / "meshes" / "arm.stl")
    urdf = tmp_path / "meshy.urdf"
    urdf.write_text(MESHY_URDF)
    robot = Robot.from_urdf(urdf)
    with caplog.at_level(logging.WARNING):
        h = harness(robot)
    text = caplog.text
    assert "mesh package://nowhere_pkg/meshes/base.stl of link base not found" in text
    assert str(tmp_path / "nowhere_pkg" / "meshes" / "base.stl") in text  # a place searched
    assert "holds nowhere_pkg with --package-path DIR" in text  # what to do about it
    assert "mesh file:///no/such/hand.dae of link hand not found" in text
    assert text.count("hand.dae of link hand not found") == 1  # once, not per use
    assert "link base is drawn with its collision geometry" in text
    assert "link hand is drawn with a placeholder box" in text
    assert "arm.stl" not in text  # found next to the URDF
    nodes = h.scene.server.scene._handle_from_node_name
    assert "/robots/meshy/links/base/visual_0" in nodes  # the collision box stands in
    assert "/robots/meshy/links/base/arm/visual_0" in nodes  # nested as the URDF's tree
    assert "/robots/meshy/links/base/arm/hand/visual_0" in nodes  # the placeholder
    arm = load_link_geometry(robot.source)["arm"].visual[0]
    assert arm.mesh is not None and arm.rgba == (0.0, 0.0, 1.0, 1.0)
    np.testing.assert_allclose(arm.mesh.extents, [0.1, 0.1, 0.3])  # scale 2 applied
    h.call(lambda: h.world.set_q([0.5, -0.5]))
    h.run(0.05)
    assert_frames_match(h, [0.5, -0.5])


def test_a_collision_mesh_stands_in_for_a_missing_visual_one(
    tmp_path: Path, harness: Callable[..., Harness]
) -> None:
    """An STL read without trimesh, standing in with no colour of its own: drawn grey."""
    trimesh.creation.box(extents=(0.05, 0.05, 0.15)).export(tmp_path / "arm.stl")
    urdf = tmp_path / "stand_in.urdf"
    urdf.write_text(
        '<robot name="stand_in"><link name="base">'
        '<visual><geometry><mesh filename="missing.stl"/></geometry></visual>'
        '<collision><geometry><mesh filename="arm.stl"/></geometry></collision></link>'
        '<joint name="j" type="revolute"><parent link="base"/><child link="tip"/>'
        '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>'
        '<link name="tip"/></robot>'
    )
    robot = Robot.from_urdf(urdf)
    h = harness(robot)
    node = h.scene.server.scene._handle_from_node_name["/robots/stand_in/links/base/visual_0"]
    assert tuple(node.color) == pytest.approx((178, 178, 184), abs=1)  # the default grey


MTL_ROBOT = ROOT / "tests" / "data" / "mtl_robot" / "robot.urdf"


def test_a_urdf_material_wins_over_the_mesh_files_own_colour(
    harness: Callable[..., Harness],
) -> None:
    """pybullet's kuka_iiwa: OBJ meshes with a near-white .mtl, URDF colours per link."""
    robot = Robot.from_urdf(MTL_ROBOT)
    links = load_link_geometry(robot.source)
    [base], [tip] = links["base"].visual, links["tip"].visual
    assert base.mesh is not None and tip.mesh is not None
    for shape in (base, tip):  # the .mtl was read: the file has a colour of its own
        assert isinstance(shape.mesh, Mesh) and shape.mesh.rgba is not None
        assert list(np.round(np.array(shape.mesh.rgba) * 255)) == [230, 230, 230, 255]
    assert base.rgba == pytest.approx((1.0, 0.423529411765, 0.0392156862745, 1.0))
    assert tip.rgba is None  # no URDF material: the file's colour is kept
    nodes = harness(robot).scene.server.scene._handle_from_node_name
    base = nodes[f"/robots/{robot.name}/links/base/visual_0"]
    assert tuple(base.color) == pytest.approx((255, 108, 10), abs=1)
