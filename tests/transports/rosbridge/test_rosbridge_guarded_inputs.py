"""Joint inputs under the guard move through the session's calls like any other move.

A guarded ``/joint_command`` is checked off the event loop and then moves (its reply was
once a coroutine nobody awaited: the arm never moved); one whose way collides is
refused and the world hears the refusal, as of a text ``move``.
"""

from __future__ import annotations

import json
import threading
from collections.abc import Callable, Iterator
from typing import Any

import pytest
from websockets.sync.client import connect
from websockets.sync.connection import Connection as ClientConnection
from world_support import WAIT_S, WorldServer

from c2rviz.errors import C2rvizError
from c2rviz.world.observer import Observer


class Refusals(Observer):
    def __init__(self) -> None:
        self.seen: list[tuple[str, str]] = []

    def on_refused(self, robot: str, source: str, line: str, error: C2rvizError) -> None:
        self.seen.append((line, str(error)))


def _command(ws: ClientConnection, line: str) -> dict[str, Any]:
    request = {"op": "call_service", "id": "c", "service": "/c2rviz/command"}
    ws.send(json.dumps(request | {"args": {"command": line}}))
    while True:
        frame = json.loads(ws.recv(timeout=WAIT_S))
        if frame.get("op") == "service_response":
            return frame


def _publish(ws: ClientConnection, position: float) -> None:
    msg = {"name": ["joint_l"], "position": [position]}
    ws.send(json.dumps({"op": "publish", "topic": "/joint_command", "msg": msg}))


def _wait(server: WorldServer, condition: Callable[[], bool], what: str) -> None:
    pause = threading.Event()
    for _ in range(int(WAIT_S / 0.01)):
        if server.call(condition):
            return
        pause.wait(0.01)
    raise AssertionError(f"timed out waiting for {what}")


@pytest.fixture
def ws(world_server: WorldServer) -> Iterator[ClientConnection]:
    with connect(world_server.url, open_timeout=WAIT_S, max_size=None) as client:
        yield client


def test_a_guarded_joint_command_moves(world_server: WorldServer, ws: ClientConnection) -> None:
    assert _command(ws, "guard on")["values"]["ok"]
    _publish(ws, 0.3)
    world = world_server.world
    _wait(world_server, lambda: world.q[1] == pytest.approx(0.3), "the guarded move")
    notes = world_server.notes_of("/joint_command")
    assert [(n.line, n.accepted) for n in notes] == [("/joint_command joint_l=0.3", True)]


def test_a_guarded_joint_command_into_a_wall_is_refused(
    world_server: WorldServer, ws: ClientConnection
) -> None:
    refusals = Refusals()
    world_server.call(lambda: world_server.world.add_observers([refusals]))
    assert _command(ws, "guard on")["values"]["ok"]
    assert _command(ws, "object wall box 0.05,2,2 0.6,0,0.9,0,0,0")["values"]["ok"]
    before = world_server.q()
    _publish(ws, 1.2)  # swings joint_l through the wall
    _wait(world_server, lambda: refusals.seen != [], "the refusal")
    ((line, why),) = refusals.seen
    assert line == "/joint_command joint_l=1.2" and "would hit wall" in why
    assert world_server.q() == before
