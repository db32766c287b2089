"""Many robots on one page: sends in slices, paced by their cost, and nothing dropped.

A send of a big cell comes in slices (``scene_send.SLICE_S``) and link poses go out
only where they changed (``adapter.PoseBatch``); these tests check that no pose is
lost on the way: a real ``ViserScene`` and a real websocket tab (``viewer_tabs``), the
tab's view of every link compared with Pinocchio's FK.
"""

from __future__ import annotations

import asyncio
import time
from collections.abc import Callable, Iterator
from typing import Any

import numpy as np
import pinocchio as pin
import pytest
from support import load_robot
from viewer_tabs import Harness, Tab

from c2rviz.view import adapter, scene_send, viser_scene
from c2rviz.view import panel as panel_module
from c2rviz.view.panel import READOUT_HZ, READOUTS_PER_S
from c2rviz.view.plots import PLOT_HZ, PLOTS_PER_S
from c2rviz.view.scene_send import REST_PER_WORK, SendScheduler
from c2rviz.world.world import World

ROBOTS = 12


@pytest.fixture
def cell() -> Iterator[Callable[..., Harness]]:
    made: list[Harness] = []

    def make(count: int = ROBOTS, **kwargs: Any) -> Harness:
        robot = load_robot("motoman_sia20d")
        names = [f"r{i}" for i in range(count)]
        origins = {n: pin.SE3(np.eye(3), np.array([2.0 * i, 0, 0])) for i, n in enumerate(names)}
        made.append(Harness(World(dict.fromkeys(names, robot), origins=origins), **kwargs))
        return made[-1]

    yield make
    for h in made:
        h.close()


def tab_poses(tab: Tab) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Each scene node's (position, wxyz) as the tab has been told (identity first)."""
    poses: dict[str, tuple[np.ndarray, np.ndarray]] = {}
    for m in list(tab.received):
        kind, name = m.get("type"), m.get("name")
        if kind not in ("SetPositionMessage", "SetOrientationMessage"):
            continue
        position, wxyz = poses.get(name, (np.zeros(3), np.array([1.0, 0.0, 0.0, 0.0])))
        if kind == "SetPositionMessage":
            position = np.array(m["position"])
        else:
            wxyz = np.array(m["wxyz"])
        poses[name] = (position, wxyz)
    return poses


def page_shows(h: Harness, tab: Tab, qs: dict[str, Any], tol: float = 1e-9) -> bool:
    """Whether the tab shows every link of every robot where FK puts it for ``qs``."""
    poses = tab_poses(tab)
    for name, q in qs.items():
        robot = h.world.robots[name].robot
        data = robot.model.createData()
        pin.framesForwardKinematics(robot.model, data, robot.configuration(q))
        prefix = f"{h.scene.views[name].prefix}/links"
        for link in robot.link_names():
            expected = data.oMf[robot.model.getFrameId(link, pin.BODY)]
            node = h.scene.views[name].link_nodes[link]
            got = pin.SE3.Identity()  # the nested frames' poses, composed down the path
            segments = node[len(prefix) + 1 :].split("/")
            for k in range(len(segments)):
                position, wxyz = poses.get(
                    "/".join([prefix, *segments[: k + 1]]),
                    (np.zeros(3), np.array([1.0, 0.0, 0.0, 0.0])),
                )
                w, x, y, z = wxyz
                got = got * pin.SE3(pin.Quaternion(w, x, y, z).toRotationMatrix(), position)
            if not (
                np.allclose(got.translation, expected.translation, atol=tol)
                and np.allclose(got.rotation, expected.rotation, atol=tol)
            ):
                return False
    return True


def test_a_cell_sent_in_slices_reaches_the_page_at_every_robots_last_pose(
    cell: Callable[..., Harness], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(scene_send, "SLICE_S", 0.0)  # one robot a slice
    slices: list[bool] = []
    draw = viser_scene.ViserScene._draw_robots

    def counted(self: viser_scene.ViserScene, deadline: float) -> bool:
        more = draw(self, deadline)
        slices.append(more)
        return more

    monkeypatch.setattr(viser_scene.ViserScene, "_draw_robots", counted)
    h = cell(hz=1000.0)
    tab = h.tab()
    rng = np.random.default_rng(3)
    last: dict[str, Any] = {}
    for _ in range(5):  # moves arrive while earlier sends are still under way
        for name, state in h.world.robots.items():
            last[name] = state.robot.random(rng)
            h.call(lambda name=name, q=last[name]: h.world.set_q(q, name))
        h.run(0.001)
    h.until(lambda: page_shows(h, tab, last), "every robot's last pose on the page")
    assert slices.count(True) >= ROBOTS - 1  # the sends did come in slices
    for name, q in last.items():
        assert h.scene.views[name].sent_q == tuple(q)


def test_a_robot_at_rest_after_a_tiny_step_is_shown_exactly(
    cell: Callable[..., Harness],
) -> None:
    h = cell(count=3, hz=1000.0)
    tab = h.tab()
    qs = {name: list(state.q) for name, state in h.world.robots.items()}
    h.until(lambda: page_shows(h, tab, qs), "the cell at home")
    qs["r1"][3] += 1e-9  # far below any tolerance a page could see: still sent
    h.call(lambda: h.world.set_q(qs["r1"], "r1"))
    h.until(lambda: page_shows(h, tab, qs, tol=1e-12), "the last, tiny step")


def test_a_pose_batch_sends_only_what_changed(cell: Callable[..., Harness]) -> None:
    h = cell(count=1)
    nodes = [h.scene.server.scene.add_frame(f"/batch/{k}") for k in range(3)]
    batch = adapter.PoseBatch(nodes)
    poses = np.tile([0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0], (3, 1))
    assert batch.queue(poses) == 0  # as created: nothing to send
    poses[1, 0] = 1e-12  # a position only
    poses[2, 3:] = [0.0, 1.0, 0.0, 0.0]  # an orientation only
    assert batch.queue(poses) == 2
    assert batch.queue(poses.copy()) == 0
    np.testing.assert_array_equal(nodes[1].position, [1e-12, 0.0, 0.0])
    np.testing.assert_array_equal(nodes[2].wxyz, [0.0, 1.0, 0.0, 0.0])


def test_plots_and_readouts_of_a_big_cell_share_a_budget(cell: Callable[..., Harness]) -> None:
    small, big = cell(count=2), cell(count=40)
    for h, count in ((small, 2), (big, 40)):
        for plots in h.scene.instruments.plots.values():
            assert plots.period_s == pytest.approx(max(1 / PLOT_HZ, count / PLOTS_PER_S))
        for readout in h.scene.instruments.readouts.values():
            assert readout.period_s == pytest.approx(max(1 / READOUT_HZ, count / READOUTS_PER_S))
    assert big.scene.instruments.plots["r0"].period_s > 1 / PLOT_HZ


def test_the_scheduler_runs_a_send_slice_by_slice_then_rests_as_long_as_it_worked() -> None:
    loop = asyncio.new_event_loop()
    starts: list[float] = []
    ends: list[float] = []
    work = [0.0]
    left = [3]

    def send() -> bool:
        began = time.thread_time()
        starts.append(loop.time())
        sum(range(50_000))  # some work
        left[0] -= 1
        if left[0] == 1:
            scheduler.request()  # a change while the send is under way
        work[0] += time.thread_time() - began
        ends.append(loop.time())
        return left[0] > 0

    scheduler = SendScheduler(0.0, send)
    try:
        scheduler.start(loop)
        while scheduler.sends < 2:
            loop.run_until_complete(asyncio.sleep(0.01))
        loop.run_until_complete(asyncio.sleep(0.05))
        # one send in three slices, then one more for the request made while it ran
        assert scheduler.sends == 2 and len(starts) == 4
        assert starts[1] >= ends[0] and starts[2] >= ends[1]  # slices one after another
        first_work = work[0]  # nearly all of it the first send's three slices
        assert starts[3] >= ends[2] + REST_PER_WORK * (first_work - (ends[3] - starts[3]))
        assert scheduler.work_s > 0.0
    finally:
        scheduler.stop()
        loop.close()


def test_a_moving_arm_is_sent_orientations_only(cell: Callable[..., Harness]) -> None:
    """The link frames nest as the URDF's tree: a revolute arm's moves turn its links'
    frames in their parents' and move no link's position (``view.link_tree``)."""
    h = cell(count=1, hz=1000.0)
    tab = h.tab()
    robot = h.world.robots["r0"].robot
    qs = {"r0": list(robot.home)}
    h.until(lambda: page_shows(h, tab, qs), "the arm at home")
    links = set(h.scene.views["r0"].link_nodes.values())
    seen = len(tab.received)
    rng = np.random.default_rng(8)
    for _ in range(5):
        qs["r0"] = robot.random(rng)
        h.call(lambda q=qs["r0"]: h.world.set_q(q, "r0"))
        h.run(0.005)
    h.until(lambda: page_shows(h, tab, qs), "the arm's last pose")
    kinds = [m["type"] for m in list(tab.received)[seen:] if m.get("name") in links]
    assert "SetOrientationMessage" in kinds
    assert "SetPositionMessage" not in kinds


def test_a_panel_sends_its_sliders_only_when_the_target_moves(
    cell: Callable[..., Harness],
) -> None:
    """A send of many robots asks each panel for its sliders at every frame: a target
    they show already sends nothing, and a slider left alone while the page moved it
    (busy) is set once it is free, though the target has not moved since."""
    h = cell(count=1)
    panel = h.scene.panels["r0"]
    sent: list[tuple[Any, Any]] = []
    real = adapter.set_gui_value

    def spy(handle: Any, value: Any, **kwargs: Any) -> bool:
        if real(handle, value, **kwargs):
            sent.append((handle, value))
            return True
        return False

    target = (0.5, -0.25, 0.3, 0.75, -0.4, 0.1, 0.2)

    def run() -> None:
        original = panel_module.adapter.set_gui_value
        panel_module.adapter.set_gui_value = spy  # type: ignore[assignment]
        try:
            first = panel.sliders[0]
            panel.show_joints(target, lambda slider: slider is first)  # the page holds 0
            assert [handle for handle, _ in sent] == panel.sliders[1:]
            sent.clear()
            panel.show_joints(target, lambda slider: False)  # free now: 0 is set
            assert sent == [(first, panel.to_slider(0, target[0]))]
            sent.clear()
            panel.show_joints(list(target), lambda slider: False)
            assert sent == []
        finally:
            panel_module.adapter.set_gui_value = original  # type: ignore[assignment]

    h.call(run)
