"""The page as a door and as a view of a cell: many robots, motion, bad input, floods.

Each test runs a real ``ViserScene`` on a real ``World`` (``viewer_tabs.Harness``)
and talks to it as pages do, over real websockets (``viewer_tabs.Tab``).
"""

from __future__ import annotations

import asyncio
import gzip
import os
import socket
import threading
import urllib.error
import urllib.request
from collections.abc import Callable, Iterator
from typing import Any

import numpy as np
import pinocchio as pin
import pytest
from support import load_robot
from viewer_tabs import Harness, Tab, bad_messages
from websockets.exceptions import InvalidStatus

from c2rviz.errors import MotionInterrupted
from c2rviz.robot.model import Robot
from c2rviz.session import Services, Session, SessionDefaults
from c2rviz.transports.tcp_server import CommandServer
from c2rviz.view import adapter
from c2rviz.view.door_rules import DoorPolicy
from c2rviz.view.panel import MAX_LABEL_CHARS, short_label
from c2rviz.view.viser_scene import ViserScene
from c2rviz.world.observer import MAX_MARKERS
from c2rviz.world.world import World


@pytest.fixture
def harness() -> Iterator[Callable[..., Harness]]:
    made: list[Harness] = []

    def make(world: World | None = None, **kwargs: Any) -> Harness:
        chosen = world if world is not None else World(load_robot())
        made.append(Harness(chosen, **kwargs))
        return made[-1]

    yield make
    for h in made:
        h.close()


def placement(handle: Any) -> pin.SE3:
    w, x, y, z = handle.wxyz
    return pin.SE3(pin.Quaternion(w, x, y, z).toRotationMatrix(), np.array(handle.position))


def fk(robot: Robot, q: Any) -> pin.Data:
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, robot.configuration(q))
    return data


# 1. a cell: several robots in one scene


def test_a_cell_draws_every_robot_at_its_origin(harness: Callable[..., Harness]) -> None:
    """Two models, one of them twice: each link's frame in the world is origin * FK."""
    motoman, fanuc = load_robot("motoman_sia20d"), load_robot("fanuc_lrmate200id")
    origins = {
        "left": pin.SE3(pin.rpy.rpyToMatrix(0.0, 0.0, 0.3), np.array([-1.0, 0.2, 0.0])),
        "right": pin.SE3(pin.rpy.rpyToMatrix(0.0, 0.0, np.pi), np.array([1.2, 0.0, 0.1])),
        "left copy": pin.SE3(np.eye(3), np.array([0.0, -1.5, 0.0])),
    }
    world = World({"left": motoman, "right": fanuc, "left copy": motoman}, origins=origins)
    h = harness(world, title="twoarms", rng=np.random.default_rng(3))
    tab = h.tab()
    rng = np.random.default_rng(4)
    for _ in range(5):
        qs = {name: state.robot.random(rng) for name, state in world.robots.items()}
        h.call(lambda qs=qs: [world.set_q(q, name) for name, q in qs.items()])
        h.until(
            lambda qs=qs: all(h.scene.views[n].sent_q == tuple(q) for n, q in qs.items()),
            "the send of every robot's new pose",
        )
        for name, state in world.robots.items():
            view = h.scene.views[name]
            data = fk(state.robot, qs[name])
            root = placement(view.root)
            assert root.isApprox(origins[name], 1e-6)
            for link in view.link_frames:
                expected = origins[name] * data.oMf[state.robot.model.getFrameId(link, pin.BODY)]
                got = root * view.link_pose(link)
                np.testing.assert_allclose(got.homogeneous, expected.homogeneous, atol=1e-6)
    roots = {view.prefix for view in h.scene.views.values()}
    assert roots == {"/robots/left", "/robots/right", "/robots/left_copy"}
    tab.wait(
        lambda: (
            {m["props"]["label"] for m in tab.received if m["type"] == "GuiFolderMessage"}
            >= {"left", "right", "left copy", "State"}
        ),
        "a folder per robot, headed by its name in the world",
    )
    assert h.scene.title == "c2rviz — twoarms"


def test_a_cell_page_moves_the_robot_of_its_folder(harness: Callable[..., Harness]) -> None:
    motoman = load_robot("motoman_sia20d")
    world = World({"a": motoman, "b": motoman})
    h = harness(world, rng=np.random.default_rng(3))
    tab = h.tab()
    tab.set(h.scene.panels["b"].sliders[0], 20.0)
    h.until(lambda: world.state("b").q[0] == pytest.approx(np.radians(20.0)), "robot b to move")
    assert world.state("a").q == motoman.home
    h.call(lambda: world.add_marker(None, (0.0, 1.0, 0.0), "cube", robot="b"))
    h.call(lambda: world.add_marker(None, (0.0, 1.0, 0.0), "cube", robot="a"))
    h.call(lambda: world.clear_markers("a"))
    h.until(lambda: ("b", "cube") in h.scene.markers.nodes, "the send that draws b's marker")
    assert h.scene.markers.count("a") == 0 and h.scene.markers.count("b") == 1
    node = h.scene.markers.nodes["b", "cube"]
    state = world.state("b")
    expected = state.origin * motoman.base_placement * motoman.ee_pose(state.q)
    np.testing.assert_allclose(node.batched_positions[0], expected.translation, atol=1e-6)


# 2. motion: the ghost, the time left, Stop and speed


def consume(reply: Any) -> None:
    if asyncio.isfuture(reply):
        reply.add_done_callback(lambda f: f.cancelled() or f.exception())


def test_the_ghost_stands_at_the_target_while_moving_and_stop_stops(
    harness: Callable[..., Harness],
) -> None:
    world = World(load_robot())
    h = harness(world, defaults=SessionDefaults(motion="follow", speed=20.0))
    tab = h.tab()
    panel, view = h.panel, h.scene.views[world.default]
    assert h.scene.sessions[world.default].motion == "follow"  # the page's moves travel
    client = Session(h.services)
    client.set_degrees(True)
    client.motion = "on"
    arrival = h.call(lambda: client.run("move 0,1,2 90,60,-60"))
    arrived: list[Any] = []
    arrival.add_done_callback(lambda f: arrived.append(f.exception()))
    target = world.state().target
    h.until(lambda: view.sent_target == target and world.q != world.robot.home, "the ghost")
    assert view.target_root.visible
    data = fk(world.robot, target)
    for link in view.target_frames:
        expected = data.oMf[world.robot.model.getFrameId(link, pin.BODY)]
        assert view.link_pose(link, view.target_frames).isApprox(expected, 1e-6), link
    assert panel.motion.value.startswith("moving, ") and panel.motion.value.endswith(" s left")
    assert [s.value for s in panel.sliders[:3]] == pytest.approx([90.0, 60.0, -60.0])
    tab.set(panel.buttons["stop"], True)  # the page's Stop, through the door
    h.until(lambda: not world.moving(world.default) and bool(arrived), "the arm to stop")
    assert isinstance(arrived[0], MotionInterrupted)
    assert "motion stopped by page" in str(arrived[0])
    h.run(0.05)
    assert world.q != pytest.approx(target)  # stopped short of it
    assert world.state().target == pytest.approx(world.q)  # at rest where it stopped
    assert view.sent_target is None and not view.target_root.visible
    assert panel.motion.value == "idle"
    assert ("stop", True) in h.scene._commands


def test_a_slider_dragged_during_a_move_preempts_it(harness: Callable[..., Harness]) -> None:
    """The page is a client like any other: its slider's move takes over a TCP client's,
    which hears `preempted by page`; the arm goes on to the page's target."""
    world = World(load_robot())
    h = harness(world, defaults=SessionDefaults(motion="on", speed=20.0))
    tab = h.tab()
    client = Session(h.services, source="tcp 1")
    client.set_degrees(True)
    client.motion = "on"
    arrival = h.call(lambda: client.run("move 0,1 90,60"))
    arrived: list[Any] = []
    arrival.add_done_callback(lambda f: arrived.append(f.exception()))
    h.until(lambda: world.q[0] > np.radians(5.0), "the move under way")
    tab.set(h.panel.sliders[0], -30.0)
    h.until(lambda: bool(arrived), "the client's reply")
    assert isinstance(arrived[0], MotionInterrupted)
    assert "preempted by page" in str(arrived[0])
    h.until(lambda: not world.moving(world.default), "the page's move to end")
    assert world.q[0] == pytest.approx(np.radians(-30.0))
    assert world.q[1] == pytest.approx(np.radians(60.0))  # `move` keeps the other targets


def test_the_speed_slider_sets_the_page_sessions_speed(harness: Callable[..., Harness]) -> None:
    world = World(load_robot())
    h = harness(world, defaults=SessionDefaults(motion="on"))
    tab = h.tab()
    session, panel = h.scene.sessions[world.default], h.panel
    tab.set(panel.speed, 35.0)
    h.until(lambda: session.speed == 35.0, "the page's speed")
    assert panel.speed.value == 35.0
    tab.set(panel.speed, 250.0)  # outside 1..100: refused, and sent back
    h.until(lambda: h.scene.page_input.refused == 1, "the refusal")
    assert session.speed == 35.0
    tab.wait(lambda: tab.values(panel.speed)[-1:] == [35.0], "the true speed back")
    tab.set(panel.sliders[0], 10.0)  # the page's move travels and the page does not wait
    h.until(lambda: world.moving(world.default), "the move to start")
    h.until(lambda: not world.moving(world.default), "the move to end", timeout_s=60)
    assert world.q[0] == pytest.approx(np.radians(10.0))


# 3. bad page input through the scene


BAD_IDS = list(bad_messages("slider", "checkbox"))


@pytest.mark.parametrize("bad", [*BAD_IDS, "over-the-frame-limit"])
def test_a_bad_message_leaves_the_world_the_page_and_other_tabs_right(
    harness: Callable[..., Harness], bad: str
) -> None:
    h = harness()
    slider, checkbox = h.panel.sliders[1], h.scene.state_panel.collision
    h.call(lambda: h.world.set_q([0.0, 0.5, 0, 0, 0, 0, 0]))
    before = h.world.q
    page, other = h.tab(), h.tab()
    buffered = adapter.buffered_messages(h.scene.server)
    if bad == "over-the-frame-limit":
        frame: bytes | str = b"\xdd" + (70_000).to_bytes(4, "big") + b"\x90" * 70_000
    else:
        frame = bad_messages(slider._impl.uuid, checkbox._impl.uuid)[bad]
    page.send(frame)
    door = adapter.door(h.scene.server)
    h.until(lambda: sum(door.refused.values()) == 1, "the door to refuse it")
    if bad == "over-the-frame-limit":
        page.wait(lambda: page.closed.is_set(), "the page to be closed")
        assert door.refused["oversize"] == 1
    h.run(0.05)
    assert h.world.q == before
    assert slider.value == pytest.approx(np.degrees(0.5)) and checkbox.value is False
    assert not any(view.collision_nodes[0].visible for view in h.scene.views.values())
    assert not [v for v in other.values(slider) if v != pytest.approx(np.degrees(0.5))]
    # The page still works for the other tab, and both see what it did.
    other.set(h.panel.sliders[0], 12.5)
    h.until(lambda: h.world.q[0] == pytest.approx(np.radians(12.5)), "a good value after")
    if not page.closed.is_set():
        page.wait(lambda: 12.5 in page.values(h.panel.sliders[0]), "the first tab to see it")
    assert h.scene.page_input.refused == 0
    assert adapter.buffered_messages(h.scene.server) <= buffered + 12  # new poses, none of it


def test_a_foreign_origin_cannot_open_the_scenes_websocket(
    harness: Callable[..., Harness],
) -> None:
    h = harness()
    with pytest.raises(InvalidStatus) as refused:
        Tab(h.scene.url, origin="http://evil.example")
    assert refused.value.response.status_code == 403
    own = h.tab(origin=f"http://127.0.0.1:{h.scene.port}")
    own.set(h.panel.sliders[0], 5.0)
    h.until(lambda: h.world.q[0] == pytest.approx(np.radians(5.0)), "the own page's move")
    assert adapter.door(h.scene.server).refused["origin"] == 1


def test_with_a_token_the_printed_url_is_the_way_in(harness: Callable[..., Harness]) -> None:
    h = harness(policy=DoorPolicy(token="s3cret"))
    assert "token=s3cret" in h.scene.url
    with pytest.raises(InvalidStatus):
        Tab(f"http://127.0.0.1:{h.scene.port}")
    tab = Tab(f"http://127.0.0.1:{h.scene.port}/?token=s3cret")
    h.tabs.append(tab)
    h.until(lambda: tab.received != [], "the scene")


@pytest.mark.parametrize("encoding", ["gzip", "identity"])
def test_the_page_is_titled_by_the_robot(harness: Callable[..., Harness], encoding: str) -> None:
    h = harness()
    request = urllib.request.Request(
        f"http://127.0.0.1:{h.scene.port}/", headers={"Accept-Encoding": encoding}
    )
    with urllib.request.urlopen(request, timeout=10) as response:
        body = response.read()
        assert int(response.headers["Content-Length"]) == len(body)
        if encoding == "gzip":
            body = gzip.decompress(body)
    assert b"<title>c2rviz \xe2\x80\x94 motoman_sia20d</title>" in body
    assert b"<title>Viser</title>" not in body


def test_a_sliders_hint_gives_the_limits_as_limits_prints_them(
    harness: Callable[..., Harness],
) -> None:
    """puma560's +-1.570796325 rad: `limits` says -89.9999999..89.9999999 deg, and so does
    the slider's hint; the slider itself stops at its last 0.1 step inside the limits."""
    from support import LIMITS_URDF

    world = World(Robot.from_urdf(LIMITS_URDF))
    h = harness(world)
    tab = h.tab()
    session = Session(h.services)
    session.set_degrees(True)
    limits = session.run("limits").removeprefix("ok ").split(",")

    def shown(slider: Any) -> dict[str, Any]:  # what the page was told of the slider
        (added,) = [m for m in tab.received if m.get("uuid") == slider._impl.uuid and "props" in m]
        return dict(added["props"])

    for i, slider in enumerate(h.panel.sliders):
        props = shown(slider)
        low, high = limits[i].split(" ")[0].split("..")
        if world.robot.joints[i].continuous:
            assert props["hint"].endswith("turns freely")
            continue
        assert props["hint"].endswith(f"limits {low}..{high}"), i
        assert float(low) <= props["min"] and props["max"] <= float(high)  # inside the limits
    props = shown(h.panel.sliders[0])
    assert props["hint"] == "joint 0: joint1 [deg], limits -89.9999999..89.9999999"
    assert (props["min"], props["max"]) == (-89.9, 89.9)


def test_long_joint_names_get_short_labels_and_keep_the_whole_in_the_hint() -> None:
    assert short_label("joint_s") == "joint_s"
    assert short_label("shoulder_pan_joint") == "shoulder_pan"
    assert short_label("shoulder_lift_joint") == "shoulder_lift"
    assert short_label("panda_joint1") == "panda_joint1"
    long = short_label("a_very_long_joint_name_indeed")
    assert len(long) == MAX_LABEL_CHARS and long.endswith("…")


# 4. floods


def rss_bytes() -> int:
    with open("/proc/self/statm") as statm:
        return int(statm.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")


class LiveViewer:
    """The program's parts on a loop thread: a world, the viser scene, the command server."""

    def __init__(self) -> None:
        self.loop = asyncio.new_event_loop()
        self.world = World(load_robot())
        self.services = Services(self.world)
        self.scene = ViserScene(self.services, "127.0.0.1", 0, 100.0)
        self.world.add_observers([self.scene])
        self.server = CommandServer(self.services)
        self.thread = threading.Thread(target=self.loop.run_forever, daemon=True)
        self.thread.start()
        self.scene.start(self.loop)
        started = asyncio.run_coroutine_threadsafe(self.server.start("127.0.0.1", 0), self.loop)
        self.port = started.result(timeout=10)[1]

    def call(self, fn: Callable[[], Any]) -> Any:
        async def on_loop() -> Any:
            return fn()

        return asyncio.run_coroutine_threadsafe(on_loop(), self.loop).result(timeout=30)

    def stop(self) -> None:
        asyncio.run_coroutine_threadsafe(self.server.stop(), self.loop).result(timeout=30)
        self.loop.call_soon_threadsafe(self.scene.stop)
        self.loop.call_soon_threadsafe(self.loop.stop)
        self.thread.join(timeout=30)
        self.loop.close()


@pytest.mark.parametrize("flood", ["mark", "where"])
def test_a_flood_from_one_client_leaves_a_bystander_right_and_in_order(flood: str) -> None:
    """While one client floods (marks, or as a yardstick wheres), another's replies stay
    correct and in order, and a page sees the end state. Timings: benchmarks/view_bench.py."""
    live = LiveViewer()
    tab = Tab(live.scene.url)
    try:
        flooder = socket.create_connection(("127.0.0.1", live.port), timeout=60)
        lines = 100_000
        data = "".join(f"{flood} {i % 997},{i // 997},0,0,0,0\n" for i in range(lines))
        if flood == "where":
            data = "where\n" * lines
        replies: list[bytes] = []

        def read_flood() -> None:
            with flooder.makefile("rb") as stream:
                replies.extend(stream.readline() for _ in range(lines))

        reader = threading.Thread(target=read_flood)
        reader.start()
        threading.Thread(target=flooder.sendall, args=(data.encode(),), daemon=True).start()
        bystander = socket.create_connection(("127.0.0.1", live.port), timeout=60)
        answers = bystander.makefile("rb")
        rng = np.random.default_rng(5)
        for _ in range(100):
            q = np.round(rng.uniform(-0.5, 0.5, 7), 4)
            values = ",".join(f"{v:g}" for v in q)
            bystander.sendall(f"joints {values}\nwhere\npose\n".encode())
            assert answers.readline() == b"ok\n"
            assert answers.readline() == f"ok {values}\n".encode()  # in order, and right
            assert answers.readline().startswith(b"ok ")
        reader.join(timeout=120)
        assert replies[: lines - 1] and all(r.startswith(b"ok") for r in replies)
        assert len(replies) == lines
        expected = MAX_MARKERS if flood == "mark" else 0
        assert live.call(lambda: live.scene.marker_count) == expected
        final = live.call(lambda: tuple(live.world.q))
        slider = live.scene.panels[live.world.default].sliders[6]
        tab.wait(
            lambda: tab.values(slider)[-1:] == [pytest.approx(np.degrees(final[6]))],
            "the page to show the bystander's last pose",
        )
        answers.close()
        bystander.close()
        flooder.close()
    finally:
        tab.close()
        live.stop()


def test_a_mark_flood_costs_o1_per_marker_and_the_page_gets_the_newest(
    harness: Callable[..., Harness],
) -> None:
    """Marks in batches (a send between each, as under a flood): the buffer does not grow."""
    h = harness()
    tab = h.tab()
    session = Session(h.services)
    figures, rss = {}, {}
    for batch in range(1, 61):
        h.call(lambda b=batch: [session.run(f"mark {b},{i},0,0,0,0") for i in range(1000)])
        h.run(0.011)  # a frame: one send
        if batch in (20, 40, 60):
            figures[batch * 1000] = adapter.buffered_messages(h.scene.server)
            rss[batch * 1000] = rss_bytes()
    assert h.scene.marker_count == MAX_MARKERS
    drawn = np.concatenate([node.batched_positions for node in h.scene.markers.nodes.values()])
    base = h.world.state().origin * h.robot.base_placement
    assert sorted(drawn[:, 1]) == pytest.approx(
        sorted(base.act(np.array([60.0, i, 0.0]))[1] for i in range(1000))
    )  # the newest 1000: batch 60's
    assert figures[60_000] <= figures[20_000] + 5, figures  # one update per node, not per mark
    assert rss[60_000] - rss[20_000] < 64 << 20, rss  # generous: the figures are in view_bench
    tab.wait(
        lambda: any(
            m["type"] == "SceneNodeUpdateMessage" and "batched_positions" in m["updates"]
            for m in tab.received
        ),
        "the tab to be sent the markers",
    )


def test_a_page_flooding_a_slider_costs_one_command_per_loop_turn(
    harness: Callable[..., Harness],
) -> None:
    """While the loop is busy, a page's values for one control wait as one: the latest."""
    h = harness()
    tab = h.tab()
    slider = h.panel.sliders[0]
    for i in range(2000):
        tab.set(slider, float(i % 80))
    tab.set(slider, 85.0)  # a value the flood never sent: seen pending, the door read them all
    pending = h.scene.page_input._handoff._pending
    tab.wait(lambda: pending.get(id(slider), (0, 0, 0))[2] == 85.0, "the door to read them all")
    assert len(pending) == 1
    h.until(lambda: h.world.q[0] == pytest.approx(np.radians(85.0)), "the last value")
    moves = [line for line, _ in h.scene._commands if line.startswith("move 0")]
    assert moves == ["move 0 85.0"]  # one command for 2001 values
    assert h.scene.page_input.refused == 0


def test_a_tab_that_closes_mid_flood_leaves_the_others_served(
    harness: Callable[..., Harness],
) -> None:
    h = harness()
    leaving, staying = h.tab(), h.tab()
    session = Session(h.services)
    h.call(lambda: [session.run("mark") for _ in range(3000)])
    leaving.close()
    h.call(lambda: session.run("joints 0.1,0,0,0,0,0,0"))
    h.run(0.05)
    staying.wait(
        lambda: any(
            m["type"] == "GuiUpdateMessage" and m["updates"].get("value") == pytest.approx(5.72958)
            for m in staying.received
        ),
        "the staying tab to see the move",
    )
    assert leaving.closed.is_set()


def test_a_viewer_beyond_loopback_gets_a_token_and_says_so(c2rviz_process: Any) -> None:
    proc = c2rviz_process("--viser-host", "0.0.0.0", "--viser-port", "0")
    assert proc.viewer_url is not None and "/?token=" in proc.viewer_url
    warning = proc.popen.stdout.readline()
    assert warning.startswith("c2rviz: warning: the viewer listens on 0.0.0.0: ")
    assert "generated for this run; --viewer-token sets one" in warning
    port = int(proc.viewer_url.split("/?")[0].rsplit(":", 1)[1])
    with pytest.raises(urllib.error.HTTPError) as refused:
        urllib.request.urlopen(f"http://127.0.0.1:{port}/", timeout=10)
    refused.value.close()
    assert refused.value.code == 403
    with pytest.raises(InvalidStatus):
        Tab(f"http://127.0.0.1:{port}/")
    tab = Tab(proc.viewer_url)  # the printed URL is the way in
    tab.wait(lambda: tab.received != [], "the scene")
    tab.close()
    with socket.create_connection(("127.0.0.1", proc.port), timeout=10) as sock:
        sock.sendall(b"quit\n")
        assert sock.recv(10) == b"ok\n"
    assert proc.wait(timeout=30) == 0
