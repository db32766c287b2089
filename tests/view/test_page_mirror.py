"""The page process's mirror, fed by the command process's frames in one process: every
effect the scene is told arrives, and the page's lines go back to the page's session
(``view/page_link``, ``view/page_process``; the two processes: test_page_process.py)."""

from __future__ import annotations

import math
import pickle
from collections.abc import Iterator
from typing import Any

import numpy as np
import pinocchio as pin
import pytest
from support import load_robot

from c2rviz.session.services import Services, SessionDefaults
from c2rviz.session.session import Session
from c2rviz.view import adapter
from c2rviz.view.page_channel import FrameReader
from c2rviz.view.page_link import IN_FLIGHT, PageLink
from c2rviz.view.page_process import ForwardingSession, PageProcess
from c2rviz.view.page_snapshot import Hello, PageConfig, snapshot
from c2rviz.world.clock import Clock
from c2rviz.world.world import World

ROBOT = "motoman_sia20d"


class Pipe:
    """Stands in for a stream writer: keeps what is written."""

    def __init__(self) -> None:
        self.data = bytearray()
        self.transport = self

    def get_write_buffer_size(self) -> int:
        return 0

    def is_closing(self) -> bool:
        return False

    def write(self, data: bytes) -> None:
        self.data += data

    def take(self) -> list[list[Any]]:
        messages = FrameReader().feed(bytes(self.data))
        self.data.clear()
        return messages


class Both:
    """The command side (world, services, link) and the page side (mirror, scene)."""

    def __init__(self, clock: Clock | None = None) -> None:
        self.world = World({ROBOT: load_robot()}, clock=clock)
        self.services = Services(self.world)
        config = PageConfig("127.0.0.1", 0, 100.0, (), None, 4, None, SessionDefaults(), 100, 30, 8)
        self.link = PageLink(self.services, config)
        self.world.add_observers([self.link])
        self.to_page, self.to_program = Pipe(), Pipe()
        hello = Hello(config, snapshot(self.services, self.link.sessions, []))
        self.page = PageProcess(pickle.loads(pickle.dumps(hello)), self.to_program)  # type: ignore[arg-type]
        self.link._writer = self.to_page  # type: ignore[assignment]
        self.link.fresh()  # as the hello does: the link notes what follows
        self.session = Session(self.services, robot=ROBOT)
        self.session.set_degrees(True)

    def frame(self) -> None:
        """One frame published and applied; then the page's lines run in the program."""
        self.link._publish()
        for message in self.to_page.take():
            self.page.apply(message)
        for message in self.to_program.take():
            self.link._heard(message)

    @property
    def mirror(self) -> Any:
        return self.page.world.robots[ROBOT]


@pytest.fixture
def both() -> Iterator[Both]:
    made = Both()
    try:
        yield made
    finally:
        made.page.scene.stop()
        made.services.close()


def test_what_the_world_does_reaches_the_mirror(both: Both) -> None:
    run = both.session.run
    for line in ("move 0,2 30,-20", "rgb 0,255,0", "marker cube", "mark", "tool 0,0,0.1,0,0,0"):
        assert run(line) == "ok", line
    assert run("object table box 0.2,0.2,0.2 0.5,0,0,0,0,0") == "ok"
    assert run("trail on") == "ok"
    both.world.set_ghost(ROBOT, False)
    both.frame()
    mirror, real = both.mirror, both.world.robots[ROBOT]
    assert mirror.q == pytest.approx(real.q) and mirror.target == pytest.approx(real.target)
    assert list(mirror.markers) == list(real.markers)
    assert mirror.tool.isApprox(real.tool)
    assert not mirror.ghost
    assert [o.name for o in both.page.world.objects[ROBOT]] == ["table"]
    assert ROBOT in both.page.services.trails.trails
    assert ("trail on", True) in both.page.scene._commands  # the panel's last commands
    assert run("clear") == "ok"
    assert run("trail off") == "ok"
    both.frame()
    assert not mirror.markers and mirror.q == pytest.approx(real.q)
    assert not both.page.services.trails.trails


def test_every_joint_sample_reaches_the_plots(both: Both) -> None:
    """A frame carries every sample since the last (the plots' history), not only the last."""
    for k in range(5):
        assert both.session.run(f"move 0 {k}") == "ok"
    both.frame()
    history = both.page.scene.instruments.histories[ROBOT]
    assert history.at(history.end)[0] == pytest.approx(0.0698131700797732)  # 4 degrees


def test_a_flood_of_lines_sends_the_page_only_the_last_commands_it_shows(both: Both) -> None:
    """Every line is noted, but a frame carries only the newest the readout keeps (8 here),
    once, not one event per line: a pipelined client's 1,000 lines cost the page nothing."""
    for k in range(1000):
        assert both.session.run(f"joints {k % 10},0,0,0,0,0,0") == "ok"
    both.link._publish()
    [frame] = both.to_page.take()
    said = [event for event in frame[3] if event[0] in ("command", "commands")]
    newest = [[f"joints {k % 10},0,0,0,0,0,0", True] for k in range(999, 991, -1)]
    assert said == [["commands", newest]]
    both.page.apply(frame)
    assert list(both.page.scene._commands)[:8] == list(both.link.commands)
    assert both.session.run("where") == "ok 9,0,0,0,0,0,0"
    both.frame()
    assert list(both.page.scene._commands)[:8] == list(both.link.commands)
    assert both.page.scene._commands[0] == ("where", True)


def test_a_page_process_that_has_not_applied_its_frames_gets_fewer_fuller_ones(
    both: Both,
) -> None:
    """Past ``IN_FLIGHT`` frames unapplied the next waits, gathering; ``applied`` lets it go."""
    for k in range(IN_FLIGHT):
        assert both.session.run(f"move 0 {k}") == "ok"
        both.link._publish()
    sent = both.to_page.take()
    assert len(sent) == IN_FLIGHT
    for k in (10, 11, 12):
        assert both.session.run(f"move 0 {k}") == "ok"
    both.link._publish()
    assert both.to_page.take() == []  # held: the page process is busy
    for frame in sent:
        both.page.apply(frame)
    said = both.to_program.take()
    assert [m[0] for m in said] == ["applied"] * IN_FLIGHT
    both.link._heard(said[0])  # one applied: one more may go
    both.link._publish()
    [frame] = both.to_page.take()
    [robot] = frame[2]
    assert [round(math.degrees(s[1])) for s in robot[1]] == [10, 11, 12]  # every sample
    both.page.apply(frame)
    assert both.mirror.q[0] == pytest.approx(math.radians(12))


def test_a_page_line_runs_on_the_page_session_in_the_program(both: Both) -> None:
    page = both.page.scene.sessions[ROBOT]
    assert isinstance(page, ForwardingSession)
    assert page.run("move 2 30.0") is None  # handed on: the page does not wait
    assert both.mirror.target[2] == pytest.approx(0.5235987755982988)  # assumed at once
    both.frame()
    assert both.session.run("where") == "ok 0,0,30,0,0,0,0"
    assert both.world.robots[ROBOT].target[2] == pytest.approx(0.5235987755982988)
    page.run("move 2 999.0")  # out of the joint's range: refused in the program
    page.run("speed 40.0")
    both.frame()
    both.frame()
    assert both.session.run("where") == "ok 0,0,30,0,0,0,0"
    assert both.link.sessions[ROBOT].speed == 40.0
    assert page.speed == 40.0


def test_a_page_that_fell_behind_gets_the_whole_world_again(both: Both) -> None:
    for line in ("move 1 10", "mark", "mark"):
        assert both.session.run(line) == "ok"
    both.link._behind = True
    both.to_page.data.clear()  # as if those frames were dropped
    assert both.session.run("move 1 20") == "ok"
    both.frame()
    assert len(both.mirror.markers) == 2
    assert both.mirror.q == pytest.approx(both.world.robots[ROBOT].q)


def drawn(both: Both) -> Any:
    """A frame applied, then the page's scene's send run to its end; the scene."""
    both.frame()
    scene = both.page.scene
    while scene._send():  # slices
        pass
    return scene


def test_parts_goals_cameras_and_the_fault_banner_reach_the_page(both: Both) -> None:
    run = both.session.run
    assert run("part p1 box 0.03,0.03,0.05 0.5,0,0.025,0,0,0") == "ok"
    assert run("goal p1 0.5,0.2,0.025,0,0,0") == "ok"
    assert run("camera top 0.5,0,1,0,90,0") == "ok"
    assert run("fault stall joint_l") == "ok"
    scene = drawn(both)
    node, label, _ = scene.parts.nodes["p1"]
    np.testing.assert_allclose(node.position, [0.5, 0, 0.025], atol=1e-9)
    assert label.text == "p1" and node.opacity is None
    goal = scene.parts.goals["p1"]
    assert goal.wireframe and tuple(goal.dimensions) == pytest.approx((0.03, 0.03, 0.05))
    np.testing.assert_allclose(goal.position, [0.5, 0.2, 0.025], atol=1e-9)
    camera, seen, _ = scene.cameras.nodes["top"]
    np.testing.assert_allclose(camera.position, [0.5, 0, 1], atol=1e-9)
    assert seen.text == "top: p1"
    banner = scene.panels[ROBOT].banner
    assert banner.visible and banner.content == "**Faults:** `stall joint_l`"
    # An object over the part hides it from the camera, in the page as in the program.
    assert run("object lid box 0.3,0.3,0.01 0.5,0,0.5,0,0,0") == "ok"
    drawn(both)
    assert seen.text == "top: none"
    both.world.cameras.blackout("top", math.inf)
    assert drawn(both).cameras.nodes["top"][1].text == "top: dark"
    for line in ("part p1 remove", "goal all remove", "camera top remove", "fault clear"):
        assert run(line) == "ok", line
    scene = drawn(both)
    assert scene.parts.nodes == {} and scene.parts.goals == {} and scene.cameras.nodes == {}
    assert not banner.visible


def test_a_held_part_follows_the_mirrors_arm(both: Both) -> None:
    """A held part's row says its link and offset: the mirror moves it with its own joint
    samples, as the world does, and the page labels it held."""
    world = both.world
    assert both.session.run("part p1 box 0.03,0.03,0.03 0.5,0,0.015,0,0,0") == "ok"
    part = world.parts.parts.get("p1")
    link = world.robots[ROBOT].robot.eelink
    part.holder, part.link, part.offset = ROBOT, link, pin.SE3.Identity()
    assert both.session.run("move 0 30") == "ok"  # the world moves p1 with the arm
    scene = drawn(both)
    mirrored = both.page.world.parts.parts.get("p1")
    assert mirrored.holder == ROBOT and mirrored.link == link
    assert mirrored.pose.isApprox(part.pose, 1e-9)
    node, label, _ = scene.parts.nodes["p1"]
    assert label.text == f"p1 (held by {ROBOT})" and node.opacity is not None
    np.testing.assert_allclose(node.position, part.pose.translation, atol=1e-9)


def test_a_page_that_fell_behind_gets_the_parts_cameras_and_banner_again(both: Both) -> None:
    for line in ("part p1 box 0.03,0.03,0.03 0.5,0,0.015,0,0,0", "camera top 0.5,0,1,0,90,0"):
        assert both.session.run(line) == "ok", line
    assert both.session.run("fault estop") == "ok"
    both.link._behind = True
    both.to_page.data.clear()  # as if those frames were dropped
    scene = drawn(both)
    assert list(scene.parts.nodes) == ["p1"] and list(scene.cameras.nodes) == ["top"]
    assert "EMERGENCY STOP" in scene.panels[ROBOT].banner.content


class Stepped(Clock):
    """Time that moves only when a test moves it (``t`` [s])."""

    def __init__(self) -> None:
        self.t = 0.0

    def now(self) -> float:
        return self.t


def test_a_trail_clear_clears_the_pages_trail() -> None:
    clock = Stepped()
    both = Both(clock)
    try:
        _trail_cleared(both, clock)
    finally:
        both.page.scene.stop()
        both.services.close()


def _trail_cleared(both: Both, clock: Stepped) -> None:
    run = both.session.run
    assert run("trail on") == "ok"
    both.frame()
    keeper, kept = both.page.services.trails, both.services.trails
    # A point per frame of the clock: move until there are 4. (Joint 1, not joint 0: at
    # home the tool is on joint 0's axis, so turning it leaves the tool where it is and
    # the trail never grew; the loop once ran 100,000 moves to its end.)
    for k in range(1, 100_000):
        clock.t += 5 * both.world.frame_s  # moves frames apart: a point each, both sides
        assert run(f"move 1 {k % 90}") == "ok"
        both.frame()
        if len(kept.points(ROBOT)) >= 4:
            break
    assert len(kept.points(ROBOT)) >= 4
    np.testing.assert_allclose(keeper.points(ROBOT), kept.points(ROBOT))
    assert run("trail clear") == "ok"
    both.frame()
    assert len(keeper.points(ROBOT)) == 1  # from where the arm is now
    np.testing.assert_allclose(keeper.points(ROBOT), kept.points(ROBOT))


def test_the_page_process_lights_its_page_as_the_program_says(monkeypatch) -> None:
    """``--viewer-lighting`` reaches the page process (its PageConfig), as it does the page
    served in the program's own process."""
    asked: list[str] = []
    start = adapter.start

    def spy(*args: Any, **kwargs: Any) -> Any:
        asked.append(kwargs["lighting"])
        return start(*args, **kwargs)

    monkeypatch.setattr(adapter, "start", spy)
    world = World({ROBOT: load_robot()})
    services = Services(world)
    config = PageConfig(
        "127.0.0.1", 0, 100.0, (), None, 4, None, SessionDefaults(), 100, 30, 8, "plain"
    )
    link = PageLink(services, config)
    hello = Hello(config, snapshot(services, link.sessions, []))
    page = PageProcess(pickle.loads(pickle.dumps(hello)), Pipe())  # type: ignore[arg-type]
    try:
        assert asked == ["plain"]
    finally:
        page.scene.stop()
        services.close()
