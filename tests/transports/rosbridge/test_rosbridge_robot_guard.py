"""Bad input at a real c2rviz server's rosbridge door: a status naming the problem, nothing
moves partly, the connection and every other door go on.

A raw websockets client sends what roslibpy would not: broken JSON, wrong types,
NaN, unknown joints, trajectories that break a limit late, a 10 MB frame, a
subscribe flood. After each refusal the arm is where it was and the same
connection still answers a service call.
"""

from __future__ import annotations

import json
from collections.abc import Iterator
from typing import Any

import pytest
from support import Client, load_robot
from websockets.exceptions import ConnectionClosed, InvalidStatus
from websockets.sync.client import connect
from websockets.sync.connection import Connection as ClientConnection
from world_support import WAIT_S, WorldServer

from c2rviz.app.config import Settings
from c2rviz.transports.rosbridge import RosbridgePolicy

HOME = load_robot("motoman_sia20d").home


def receive(ws: ClientConnection) -> dict[str, Any]:
    frame = ws.recv(timeout=WAIT_S)
    assert isinstance(frame, str)
    answer = json.loads(frame)
    assert isinstance(answer, dict)
    return answer


def ask(ws: ClientConnection, frame: dict[str, Any] | str) -> dict[str, Any]:
    ws.send(frame if isinstance(frame, str) else json.dumps(frame))
    return receive(ws)


def command(ws: ClientConnection, line: str) -> dict[str, Any]:
    request = {"op": "call_service", "id": "c", "service": "/c2rviz/command"}
    return ask(ws, request | {"args": {"command": line}})


@pytest.fixture
def ws(world_server: WorldServer) -> Iterator[ClientConnection]:
    with connect(world_server.url, open_timeout=WAIT_S, max_size=None) as client:
        yield client


def trajectory(*points: tuple[float, list[float]], names: list[str] | None = None) -> dict:
    return {
        "joint_names": names or ["joint_s", "joint_l"],
        "points": [
            {"positions": p, "time_from_start": {"sec": int(t), "nanosec": round(t % 1 * 1e9)}}
            for t, p in points
        ],
    }


def publish(topic: str, msg: dict[str, Any] | str, id: str = "p") -> str:
    shown = msg if isinstance(msg, str) else json.dumps(msg)
    return f'{{"op": "publish", "id": "{id}", "topic": "{topic}", "msg": {shown}}}'


BAD = [
    ("not json {", None, "frame is not valid JSON"),
    ('"a string"', None, "frame must be a JSON object, not a string"),
    ('{"op": "jump", "id": "j"}', "j", "unknown op 'jump'"),
    ('{"op": "subscribe", "id": "s"}', "s", "subscribe: topic is missing"),
    ('{"op": "call_service", "id": "c1"}', "c1", "call_service: service is missing"),
    ('{"op": "subscribe", "id": "s", "topic": 5}', "s", "topic must be a string, not an integer"),
    (publish("/c2rviz/command", {"data": 5}), "p", "std_msgs/msg/String: data must be a string"),
    (
        publish("/joint_command", '{"name": ["joint_s"], "position": [NaN]}'),
        None,  # a frame that is not JSON has no id to read
        "frame is not valid JSON (NaN is not a JSON number",
    ),
    (
        publish("/joint_command", '{"name": ["joint_s"], "position": [1e999]}'),
        None,
        "is too large for a float",
    ),
    (
        publish("/joint_command", {"name": ["joint_s", "wrist"], "position": [0.5, 0.5]}),
        "p",
        "name[1]: 'wrist' is not a joint of motoman_sia20d's chain",
    ),
    (
        publish("/joint_command", {"name": ["joint_s", "joint_l"], "position": [0.5, 9.0]}),
        "p",
        "joint_l (index 1) = 9 rad is outside its limits",
    ),
    (
        publish("/joint_trajectory", trajectory((1.0, [0.1, 0.1]), (1.0, [0.2, 0.2]))),
        "p",
        "points[1].time_from_start is not after points[0]",
    ),
    (
        publish("/joint_trajectory", trajectory((1.0, [0.1, 0.1]), (4.0, [0.2, 9.0]))),
        "p",
        "points[1].positions: joint_l = 9 rad is outside its limits",
    ),
    (
        publish("/joint_trajectory", trajectory((1.0, [0.1, 0.1]), (1.1, [2.0, 0.2]))),
        "p",
        "on the way to points[1]: joint_s velocity reaches",
    ),
    (
        publish("/joint_trajectory", trajectory((1.0, [0.1, 0.1]), names=["joint_s", "hand"])),
        "p",
        "joint_names[1]: 'hand' is not a joint",
    ),
    (
        publish("/joint_states", {"name": [], "position": []}),
        "p",
        "/joint_states is not a topic c2rviz takes messages on",
    ),
    (
        '{"op": "subscribe", "id": "s", "topic": "/joint_command"}',
        "s",
        "/joint_command is a topic c2rviz takes messages on, not one it publishes",
    ),
    (publish("/c2rviz/command", {"data": "joints 1\njoints 2"}), "p", "one line per message"),
    (publish("/c2rviz/command", {"data": "x" * 9000}), "p", "line too long (limit 8192 bytes)"),
    (publish("/c2rviz/command", {"data": "jonts 1,2"}), "p", "unknown command 'jonts'"),
]


@pytest.mark.parametrize(("frame", "id", "text"), BAD, ids=[b[2][:40] for b in BAD])
def test_bad_input_gets_a_status_and_moves_nothing(
    world_server: WorldServer, ws: ClientConnection, frame: str, id: str | None, text: str
) -> None:
    status = ask(ws, frame)
    assert status["op"] == "status" and status["level"] == "error"
    assert status.get("id") == id
    assert text in status["msg"]
    assert world_server.q() == HOME  # nothing moved, not partly either
    assert command(ws, "where")["values"]["ok"] is True  # the connection goes on


def test_a_refused_trajectory_leaves_a_running_one_alone(
    world_server: WorldServer, ws: ClientConnection
) -> None:
    ws.send(publish("/joint_trajectory", trajectory((1.0, [0.2, 0.1]), (60.0, [0.3, 0.1]))))
    assert command(ws, "where")["values"]["ok"]  # taken
    status = ask(ws, publish("/joint_trajectory", trajectory((1.0, [0.1, 0.1]))))
    assert "a trajectory starts from rest and the arm is moving" in status["msg"]
    assert command(ws, "stop")["values"] == {"reply": "ok", "ok": True}  # at rest on the path
    q = world_server.q()
    assert 0.0 < q[0] < 0.3 and q[2:] == HOME[2:]


def test_an_oversized_frame_closes_only_its_connection(
    world_server: WorldServer, ws: ClientConnection
) -> None:
    with connect(world_server.url, open_timeout=WAIT_S, max_size=None) as big:
        big.send(publish("/c2rviz/command", {"data": "x" * (10 << 20)}))
        with pytest.raises(ConnectionClosed) as closed:
            big.recv(timeout=WAIT_S)
        assert closed.value.rcvd is not None and closed.value.rcvd.code == 1009  # message too big
    assert command(ws, "joints 0.1,0,0,0,0,0,0")["values"]["ok"]  # the other connection
    client = Client("127.0.0.1", world_server.ports["motoman_sia20d"], timeout=WAIT_S)
    try:
        assert client.ask("where") == "ok 0.1,0,0,0,0,0,0"  # and the text port go on
    finally:
        client.close()


def test_a_subscribe_flood_is_capped(world_server: WorldServer, ws: ClientConnection) -> None:
    limit = RosbridgePolicy().max_subscriptions
    for k in range(limit + 50):
        ws.send(json.dumps({"op": "subscribe", "id": f"s{k}", "topic": "/c2rviz/events"}))
    refused = [receive(ws) for _ in range(50)]
    assert all("too many subscriptions on this connection (limit 64)" in s["msg"] for s in refused)
    assert [s["id"] for s in refused] == [f"s{k}" for k in range(limit, limit + 50)]
    assert world_server.call(lambda: world_server.door.bridge.hub.count("/c2rviz/events")) == 1
    assert command(ws, "where")["values"]["ok"]


def test_the_guard_refuses_a_colliding_trajectory_whole(
    world_server: WorldServer, ws: ClientConnection
) -> None:
    assert command(ws, "guard on")["values"]["ok"]
    assert command(ws, "object wall box 0.05,2,2 0.6,0,0.9,0,0,0")["values"]["ok"]
    swing = trajectory((2.0, [0.0, 1.2]), (4.0, [0.0, 0.0]))  # through the wall and back
    status = ask(ws, publish("/joint_trajectory", swing))
    assert "would hit wall" in status["msg"]
    assert world_server.q() == HOME


def test_a_foreign_browser_and_a_missing_token_are_refused() -> None:
    settings = Settings(viewer_origins=("https://dash.example.org",), viewer_token="s3cret")
    server = WorldServer({"motoman_sia20d": load_robot("motoman_sia20d")}, settings=settings)
    try:
        base = f"ws://127.0.0.1:{server.port}/"
        assert server.url == base + "?token=s3cret"
        with pytest.raises(InvalidStatus, match="403"):
            connect(base, open_timeout=WAIT_S).close()
        with pytest.raises(InvalidStatus, match="403"):
            connect(server.url, origin="https://evil.example.com", open_timeout=WAIT_S).close()
        with connect(server.url, origin="https://dash.example.org", open_timeout=WAIT_S) as ok:
            assert command(ok, "where")["values"]["ok"]
    finally:
        server.stop()


def test_a_trajectorys_plan_and_checks_run_off_the_loop(
    world_server: WorldServer, ws: ClientConnection, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Issue 35, stall 3: a long trajectory's plan, limit check and guard check run on the
    session's worker, not on the event loop (whose other clients would wait for them)."""
    import threading

    from c2rviz.session import calls
    from c2rviz.transports.rosbridge import inputs

    threads: list[tuple[str, str]] = []

    def spy(name: str, real: Any) -> Any:
        def wrapped(*args: Any, **kwargs: Any) -> Any:
            threads.append((name, threading.current_thread().name))
            return real(*args, **kwargs)

        return wrapped

    monkeypatch.setattr(inputs, "plan_trajectory", spy("plan", inputs.plan_trajectory))
    monkeypatch.setattr(calls, "_check", spy("check", calls._check))
    assert command(ws, "guard on")["values"]["ok"]
    assert command(ws, "object wall box 0.05,2,2 0.6,0,0.9,0,0,0")["values"]["ok"]
    swing = trajectory((2.0, [0.0, 1.2]), (4.0, [0.0, 0.0]))  # through the wall and back
    status = ask(ws, publish("/joint_trajectory", swing))
    assert "would hit wall" in status["msg"]  # the same refusal
    assert world_server.q() == HOME
    assert [name for name, _ in threads] == ["plan", "check"]
    assert all(thread.startswith("c2rviz-work") for _, thread in threads), threads
    ws.send(publish("/joint_trajectory", trajectory((1.0, [0.1, 0.1]))))  # taken, then played
    assert command(ws, "where")["values"]["ok"]
    assert [name for name, _ in threads] == ["plan", "check"] * 2
    assert all(thread.startswith("c2rviz-work") for _, thread in threads), threads
