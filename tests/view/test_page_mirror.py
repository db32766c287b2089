"""The page process's mirror, fed by the command process's frames in one process: every
effect the scene is told arrives, and the page's lines go back to the page's session
(``view/page_link``, ``view/page_process``; the two processes: test_page_process.py)."""

from __future__ import annotations

import pickle
from collections.abc import Iterator
from typing import Any

import pytest
from support import load_robot

from c2rviz.session.services import Services
from c2rviz.session.session import Session
from c2rviz.session.settings import SessionDefaults
from c2rviz.view.page_channel import FrameReader
from c2rviz.view.page_link import PageLink
from c2rviz.view.page_process import ForwardingSession, PageProcess
from c2rviz.view.page_snapshot import Hello, PageConfig, snapshot
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

    def __init__(self) -> None:
        self.world = World({ROBOT: load_robot()})
        self.services = Services(self.world)
        config = PageConfig("127.0.0.1", 0, 100.0, (), None, 4, None, SessionDefaults(), 100, 30, 8)
        self.link = PageLink(self.services, config)
        self.world.add_observers([self.link])
        self.to_page, self.to_program = Pipe(), Pipe()
        hello = Hello(config, snapshot(self.services, self.link.sessions, []))
        self.page = PageProcess(pickle.loads(pickle.dumps(hello)), self.to_program)  # type: ignore[arg-type]
        self.link._writer = self.to_page  # type: ignore[assignment]
        self.session = Session(self.services, robot=ROBOT)
        self.session.set_degrees(True)

    def frame(self) -> None:
        """One frame published and applied; then the page's lines run in the program."""
        self.link._publish()
        for message in self.to_page.take():
            self.page.apply(message)
        for message in self.to_program.take():
            self.link._line(message[1], message[2])

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
