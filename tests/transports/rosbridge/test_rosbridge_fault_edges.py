"""Issue 38's rough edges at the rosbridge door: ``fault latency`` delays the command
service's answers, errors alike (on the virtual clock), and ``fault disconnect`` closes
the websockets bound to the robot (code 1012: they may come back), not the others."""

from __future__ import annotations

import itertools
import json
from collections.abc import Iterator
from typing import Any

import pytest
from support import load_robot
from websockets.exceptions import ConnectionClosed
from websockets.sync.client import ClientConnection, connect
from world_support import WAIT_S, WorldServer, text_client

from c2rviz.world.virtual_clock import VirtualClock

_ids = itertools.count(1)


def call(ws: ClientConnection, line: str, service: str = "/c2rviz/command") -> dict[str, Any]:
    """Call ``service`` (the command service: ``line``) and return its service_response."""
    id = f"call{next(_ids)}"
    args = {"command": line} if service == "/c2rviz/command" else {}
    ws.send(json.dumps({"op": "call_service", "service": service, "args": args, "id": id}))
    while True:
        frame = json.loads(ws.recv(timeout=WAIT_S))
        if frame.get("op") == "service_response" and frame.get("id") == id:
            return frame


def closed_code(ws: ClientConnection) -> int | None:
    """The close code the server sent, once it closed the connection."""
    try:
        while True:
            ws.recv(timeout=WAIT_S)
    except ConnectionClosed as closed:
        return closed.rcvd.code if closed.rcvd is not None else None


@pytest.fixture
def virtual_server() -> Iterator[WorldServer]:
    server = WorldServer({"motoman_sia20d": load_robot("motoman_sia20d")}, clock=VirtualClock())
    try:
        yield server
    finally:
        server.stop()


def test_latency_delays_the_services_answers_errors_alike(virtual_server: WorldServer) -> None:
    server = virtual_server

    def now() -> float:
        return server.call(lambda: server.world.clock.now())

    with connect(server.url, open_timeout=WAIT_S) as ws:
        start = now()
        assert call(ws, "bogus")["values"]["ok"] is False
        assert now() == start  # no latency: at once
        assert call(ws, "fault latency 300")["values"] == {"reply": "ok", "ok": True}
        for line, ok in [("where", True), ("bogus", False), ("joints 9,9,9,9,9,9,9", False)]:
            start = now()
            answer = call(ws, line)["values"]
            assert answer["ok"] is ok and answer["reply"].startswith("ok" if ok else "error:")
            assert now() - start == pytest.approx(0.3), line
        assert call(ws, "fault clear latency")["values"]["ok"] is True
        start = now()
        assert call(ws, "where")["values"] == {"reply": "ok 0,0,0,0,0,0,0", "ok": True}
        assert now() == start


def test_disconnect_closes_the_websockets_bound_to_the_robot(world_server: WorldServer) -> None:
    url = world_server.url
    with (
        connect(url, open_timeout=WAIT_S) as bound,
        connect(url, open_timeout=WAIT_S) as watcher,
        connect(url, open_timeout=WAIT_S) as asker,
    ):
        assert call(bound, "where")["values"]["ok"] is True  # it has a session on the robot
        assert call(watcher, "", "/rosapi/topics")["result"] is True  # no robot's
        text = text_client(world_server)
        try:
            assert text.ask("fault disconnect") == "ok"
            assert text.closed_by_server()
        finally:
            text.close()
        assert closed_code(bound) == 1012  # service restart: it may come back
        assert "/joint_states" in call(watcher, "", "/rosapi/topics")["values"]["topics"]
        # a client that cuts the robot off itself hears its answer first
        assert call(asker, "fault disconnect")["values"] == {"reply": "ok", "ok": True}
        assert closed_code(asker) == 1012
        assert "/tf" in call(watcher, "", "/rosapi/topics")["values"]["topics"]
    with connect(url, open_timeout=WAIT_S) as again:  # it may come back
        assert call(again, "faults")["values"] == {"reply": "ok none", "ok": True}
