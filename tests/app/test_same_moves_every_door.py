"""The same moves through every door: the same notes, recordings and refusals (issue 35).

One server per door (a world, the text port, the CRCL door, the rosbridge door and the
page, on one loop in a thread), each driven as its clients drive it over real sockets:
a text client's ``move``, a CRCL ``ActuateJoints``, a rosbridge ``/joint_command`` and
the page's joint slider. Each door sends joint_s to 0.5 rad (taken), then to 9 rad
(outside its limits: refused). What the world's observers hear of the door's source,
and what a recording of it keeps, must be the same whichever door the moves came by.
"""

from __future__ import annotations

import asyncio
import json
import math
import re
import socket
import threading
from collections.abc import Callable, Coroutine, Iterator
from concurrent.futures import Future
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pytest
from support import Client, load_robot
from viewer_tabs import Tab
from websockets.sync.client import connect

from c2rviz.app.config import Settings
from c2rviz.app.doors import RosbridgeDoor
from c2rviz.errors import C2rvizError, JointLimitError
from c2rviz.session import Services, Session, SessionDefaults
from c2rviz.transports.crcl.server import CrclServer
from c2rviz.transports.tcp_server import CommandServer
from c2rviz.view.viser_scene import ViserScene
from c2rviz.world.observer import Observer
from c2rviz.world.world import World

WAIT_S = 60.0
TAKEN, REFUSED = 0.5, 9.0  # joint_s [rad]: within its limits (±3.14), and far outside
DOORS = ["text", "crcl", "rosbridge", "page"]


@dataclass
class Told(Observer):
    """What the world's observers hear of commands, by source."""

    notes: list[tuple[str, str, bool]] = field(default_factory=list)
    refusals: list[tuple[str, str, C2rvizError]] = field(default_factory=list)
    replies: list[tuple[str, str, str]] = field(default_factory=list)

    def on_command(self, source: str, line: str, accepted: bool) -> None:
        self.notes.append((source, line, accepted))

    def on_refused(self, robot: str, source: str, line: str, error: C2rvizError) -> None:
        self.refusals.append((source, line, error))

    def on_reply(self, source: str, line: str, reply: str) -> None:
        self.replies.append((source, line, reply))


class Doors:
    """A world with all four doors on one loop in a thread."""

    def __init__(self, folder: Path) -> None:
        self.loop = asyncio.new_event_loop()
        self.thread = threading.Thread(target=self.loop.run_forever, daemon=True)
        self.thread.start()
        self.run(self._start(folder))

    async def _start(self, folder: Path) -> None:
        self.world = World(load_robot("motoman_sia20d"))
        self.told = Told()
        self.world.add_observers([self.told])
        defaults = SessionDefaults(motion="on")
        self.services = Services(self.world, defaults=defaults, record_dir=folder)
        self.text = CommandServer(self.services, on_quit=lambda: None)
        _, self.text_port = await self.text.start("127.0.0.1", 0)
        self.crcl = CrclServer(self.services)
        _, self.crcl_port = await self.crcl.start("127.0.0.1", 0)
        self.rosbridge = RosbridgeDoor(self.services, Settings(), lambda: None)
        await self.rosbridge.start("127.0.0.1", 0)
        self.scene = ViserScene(self.services, "127.0.0.1", 0, 100.0)
        self.world.add_observers([self.scene])
        self.scene.start(self.loop)
        self.recorder = Session(self.services, "test")  # starts and stops the recording
        self.recorder.run("record same")

    def run(self, coroutine: Coroutine[Any, Any, Any]) -> Any:
        return asyncio.run_coroutine_threadsafe(coroutine, self.loop).result(WAIT_S)

    def call(self, fn: Callable[..., Any], *args: Any) -> Any:
        done: Future[Any] = Future()

        def call() -> None:
            try:
                done.set_result(fn(*args))
            except BaseException as error:
                done.set_exception(error)

        self.loop.call_soon_threadsafe(call)
        return done.result(WAIT_S)

    def until(self, condition: Callable[[], bool], what: str) -> None:
        """Wait (polling the loop's state) until ``condition`` holds on the loop."""
        waited = threading.Event()
        for _ in range(int(WAIT_S / 0.01)):
            if self.call(condition):
                return
            waited.wait(0.01)
        raise AssertionError(f"timed out waiting for {what}")

    def stop(self) -> None:
        async def stop() -> None:
            await self.rosbridge.stop()
            await self.crcl.stop()
            await self.text.stop()
            self.scene.stop()
            self.services.close()

        self.run(stop())
        self.loop.call_soon_threadsafe(self.loop.stop)
        self.thread.join(WAIT_S)
        self.loop.close()


@pytest.fixture
def doors(tmp_path: Path) -> Iterator[Doors]:
    made = Doors(tmp_path)
    try:
        yield made
    finally:
        made.stop()


# Each door, driven as its clients drive it.


def _text(doors: Doors) -> str:
    client = Client("127.0.0.1", doors.text_port)
    try:
        assert client.ask(f"move 0 {TAKEN!r}") == "ok"
        assert client.ask(f"move 0 {REFUSED!r}").startswith("error: joint_s (index 0)")
        return "tcp 127.0.0.1:" + str(client.sock.getsockname()[1])
    finally:
        client.close()


def _crcl_doc(kind: str, command_id: int, body: str = "") -> bytes:
    xsi = "http://www.w3.org/2001/XMLSchema-instance"
    return (
        f'<?xml version="1.0" encoding="UTF-8"?>\n<CRCLCommandInstance xmlns:xsi="{xsi}">\n'
        f'  <CRCLCommand xsi:type="{kind}Type">\n    <CommandID>{command_id}</CommandID>\n'
        f"{body}\n  </CRCLCommand>\n</CRCLCommandInstance>\n"
    ).encode()


def _actuate(command_id: int, position: float) -> bytes:
    return _crcl_doc(
        "ActuateJoints",
        command_id,
        "    <ActuateJoint>\n      <JointNumber>1</JointNumber>\n"
        f"      <JointPosition>{position!r}</JointPosition>\n"
        '      <JointDetails xsi:type="JointSpeedAccelType"></JointDetails>\n'
        "    </ActuateJoint>",
    )


def _crcl_final(sock: socket.socket, command_id: int, buffer: list[bytes]) -> str:
    """Read statuses until ``command_id`` is Done or Error; return its state."""
    while True:
        data = b"".join(buffer)
        while b"</CRCLStatus>" in data:
            cut = data.index(b"</CRCLStatus>") + len(b"</CRCLStatus>")
            status, data = data[:cut].decode(), data[cut:]
            found = re.search(r"<CommandID>(\d+)</CommandID>", status)
            state = re.search(r"<CommandState>(\w+)</CommandState>", status)
            assert found and state
            if int(found[1]) == command_id and state[1] in ("CRCL_Done", "CRCL_Error"):
                buffer[:] = [data]
                return state[1]
        chunk = sock.recv(65536)
        assert chunk, "the CRCL door closed"
        buffer[:] = [data + chunk]


def _crcl(doors: Doors) -> str:
    with socket.create_connection(("127.0.0.1", doors.crcl_port), timeout=WAIT_S) as sock:
        buffer: list[bytes] = []
        sock.sendall(_crcl_doc("InitCanon", 1))
        assert _crcl_final(sock, 1, buffer) == "CRCL_Done"
        sock.sendall(_actuate(2, TAKEN))
        assert _crcl_final(sock, 2, buffer) == "CRCL_Done"
        sock.sendall(_actuate(3, REFUSED))
        assert _crcl_final(sock, 3, buffer) == "CRCL_Error"
        return "crcl 127.0.0.1:" + str(sock.getsockname()[1])


def _rosbridge(doors: Doors) -> str:
    url = f"ws://127.0.0.1:{doors.rosbridge.port}/"
    with connect(url, open_timeout=WAIT_S) as ws:
        source = "rosbridge 127.0.0.1:" + str(ws.socket.getsockname()[1])
        for position in (TAKEN, REFUSED):
            msg = {"name": ["joint_s"], "position": [position]}
            ws.send(json.dumps({"op": "publish", "topic": "/joint_command", "msg": msg}))
        status = json.loads(ws.recv(timeout=WAIT_S))  # the refusal's
        assert status["op"] == "status" and "joint_s (index 0)" in status["msg"], status
        return source


def _page(doors: Doors) -> str:
    panel = doors.scene.panels[doors.world.default]
    tab = Tab(doors.scene.url)
    try:
        tab.set(panel.sliders[0], math.degrees(TAKEN))
        doors.until(lambda: any(n[0] == "page" for n in doors.told.notes), "the page's move")
        tab.set(panel.sliders[0], math.degrees(REFUSED))
        doors.until(lambda: doors.scene.page_input.refused == 1, "the page's refusal")
    finally:
        tab.close()
    return "page"


SEND = {"text": _text, "crcl": _crcl, "rosbridge": _rosbridge, "page": _page}


def _heard(doors: Doors, source: str) -> dict[str, Any]:
    """What the observers heard of ``source``'s moves, without the door's own spelling
    (a CRCL connection's InitCanon is no move): whether each was taken, each refusal's
    error and joint, and whether each move's reply (in the order of the moves: a reply
    on arrival may come after a later refusal) was an error."""
    told = doors.told
    moves = [(line, ok) for s, line, ok in told.notes if s == source and "InitCanon" not in line]
    answered = {line: reply for s, line, reply in told.replies if s == source}
    return {
        "notes": [ok for _, ok in moves],
        "refusals": [
            (type(e).__name__, e.index if isinstance(e, JointLimitError) else None)
            for s, _, e in told.refusals
            if s == source
        ],
        "replies": [answered[line].startswith("error: ") for line, _ in moves if line in answered],
    }


def _recorded(doors: Doors, folder: Path, source: str) -> tuple[str, bool]:
    """The recording's last ``joints`` line, and whether its header names ``source``."""

    async def stop() -> Any:
        reply = doors.recorder.run("record stop")
        return reply if isinstance(reply, str) else await reply

    stopped = doors.run(stop())
    assert stopped.startswith("ok recorded same"), stopped
    (txt,) = folder.rglob("same*.txt")
    text = txt.read_text()
    joints = [line for line in text.splitlines() if line.startswith("joints ")]
    header = [line for line in text.splitlines() if line.startswith("#")]
    return joints[-1], any(source in line for line in header)


@pytest.mark.parametrize("door", DOORS)
def test_the_same_moves_through_each_door(doors: Doors, tmp_path: Path, door: str) -> None:
    source = SEND[door](doors)
    doors.until(lambda: not doors.world.moving(doors.world.default), "the arm at rest")
    doors.until(lambda: len(_heard(doors, source)["replies"]) == 2, "both replies told")
    assert _heard(doors, source) == {
        "notes": [True, False],  # the move taken, the one outside the limits refused
        "refusals": [("JointLimitError", 0)],
        "replies": [False, True],  # an ok, then an error
    }
    assert doors.call(lambda: doors.world.q)[0] == pytest.approx(TAKEN, abs=1e-12)
    last, named = _recorded(doors, tmp_path, source)
    assert last == "joints 0.5,0.0,0.0,0.0,0.0,0.0,0.0"  # the same line from every door
    assert named, f"the recording's header names {source}"
