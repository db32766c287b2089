"""Issue 35, stall 3: a frame over ``DECODE_ON_LOOP_BYTES`` is decoded, and its message
read, in the rosbridge door's decoding process (``transports.parse_process``). Other
clients go on meanwhile, the message is read once (there, not on the loop), and a
decoding process that dies costs that frame an error status; the next starts anew. A
large trajectory naming a joint the arm lacks is refused there: only its outline comes
back, and its client hears what it would hear of a small one."""

from __future__ import annotations

import json
import os
import signal
import threading
import time
from collections.abc import Callable
from typing import Any

import pytest
from rosbridge_support import CounterBridge, ServerThread
from websockets.sync.client import connect
from websockets.sync.connection import Connection as ClientConnection
from world_support import WAIT_S, WorldServer

from c2rviz.transports.parse_process import ParseProcess
from c2rviz.transports.rosbridge import messages
from c2rviz.transports.rosbridge.connection import DECODE_ON_LOOP_BYTES
from c2rviz.transports.rosbridge.inputs import joint_trajectory

HUGE = 10**400  # 401 digits: JSON allows it, a float64 cannot hold it
CALL = {"op": "call_service", "service": "/c2rviz/command"}
pytestmark = pytest.mark.skipif(not hasattr(signal, "SIGSTOP"), reason="POSIX signals")


def inbox(data: str, id: str | None = None) -> str:
    frame: dict[str, Any] = {"op": "publish", "topic": "/inbox", "msg": {"data": data}}
    return json.dumps(frame | ({"id": id} if id else {}))


def until(condition: Callable[[], object]) -> None:
    """Wait for ``condition`` (a state of the server's own thread) to come true."""
    deadline = time.monotonic() + WAIT_S
    while not condition():
        assert time.monotonic() < deadline, "the condition never came true"
        time.sleep(0.01)


def decoding(rosbridge: ServerThread) -> ParseProcess:
    process = rosbridge.server.decoding
    assert isinstance(process, ParseProcess)
    return process


def test_others_go_on_while_a_large_frame_decodes(
    rosbridge: ServerThread, bridge: CounterBridge
) -> None:
    """The decoding process is stopped (SIGSTOP) while it holds a large frame: another
    client is answered meanwhile; the large frame's client keeps its order."""
    data = "y" * (4 * DECODE_ON_LOOP_BYTES)
    with connect(rosbridge.url, open_timeout=WAIT_S) as big, connect(rosbridge.url) as other:
        big.send(inbox(data))  # (its process starts)
        assert bridge.published.get(timeout=WAIT_S)[2] == data
        process = decoding(rosbridge)
        assert process.pid is not None
        os.kill(process.pid, signal.SIGSTOP)
        try:
            big.send(inbox(data + "z"))
            big.send(json.dumps(CALL | {"id": "after", "args": {"command": "after"}}))
            until(lambda: process.busy)
            other.send(json.dumps(CALL | {"id": "o", "args": {"command": "meanwhile"}}))
            answer = json.loads(other.recv(timeout=WAIT_S))
            assert answer["values"] == {"reply": "did meanwhile", "ok": True}
            assert process.busy and bridge.published.empty()
        finally:
            os.kill(process.pid, signal.SIGCONT)
        assert json.loads(big.recv(timeout=WAIT_S))["values"]["reply"] == "did after"
        assert bridge.published.get(timeout=WAIT_S)[2] == data + "z"  # before "after"


def test_a_large_message_is_read_once_in_the_process(
    rosbridge: ServerThread, bridge: CounterBridge, monkeypatch
) -> None:
    """The message of a large frame is read (checked) in the decoding process, and the
    bridge's reader, called on the loop, takes that reading: no read in the server's
    own process; an error found there is the one the client hears."""
    from c2rviz.transports.rosbridge import messages

    reads: list[str] = []
    real = messages._Reader

    class Counted(real):  # type: ignore[misc, valid-type]
        def __init__(self, type_name: str) -> None:
            reads.append(threading.current_thread().name)
            super().__init__(type_name)

    monkeypatch.setattr(messages, "_Reader", Counted)
    names = [f"joint_{i}" for i in range(3000)]
    with connect(rosbridge.url, open_timeout=WAIT_S) as client:
        msg = {"name": names, "position": [0.25] * 3000}
        client.send(json.dumps({"op": "publish", "topic": "/joint_command", "msg": msg}))
        taken = bridge.published.get(timeout=WAIT_S)[2]
        assert taken.names == tuple(names) and taken.positions == (0.25,) * 3000
        msg["position"][2999] = HUGE
        client.send(json.dumps({"op": "publish", "id": "p", "topic": "/joint_command", "msg": msg}))
        status = json.loads(client.recv(timeout=WAIT_S))
        assert status["op"] == "status" and status["id"] == "p"
        assert "position[2999] is an integer too large for a float64" in status["msg"]
        small = {"name": ["joint_0"], "position": [HUGE]}
        client.send(json.dumps({"op": "publish", "topic": "/joint_command", "msg": small}))
        status = json.loads(client.recv(timeout=WAIT_S))
        assert "position[0] is an integer too large for a float64" in status["msg"]
    assert len(reads) == 1  # the small one's, on the loop
    assert decoding(rosbridge).started == 1


def test_a_decoding_process_that_dies_costs_one_frame(
    rosbridge: ServerThread, bridge: CounterBridge
) -> None:
    """Killed while it decodes, the process costs that frame an error status that says
    so; the connection goes on, and the next large frame starts a new process."""
    data = "w" * (2 * DECODE_ON_LOOP_BYTES)
    with connect(rosbridge.url, open_timeout=WAIT_S) as client:
        client.send(json.dumps({"op": "set_level", "level": "error"}))
        client.send(inbox(data))
        assert bridge.published.get(timeout=WAIT_S)[2] == data
        process = decoding(rosbridge)
        first = process.pid
        assert first is not None
        os.kill(first, signal.SIGSTOP)
        client.send(inbox(data + "lost", "lost"))
        until(lambda: process.busy)
        os.kill(first, signal.SIGKILL)
        status = json.loads(client.recv(timeout=WAIT_S))
        assert status["op"] == "status" and status["level"] == "error", status
        assert "the rosbridge decoding process ended without an answer" in status["msg"]
        client.send(inbox(data + "next"))
        assert bridge.published.get(timeout=WAIT_S)[2] == data + "next"
    assert process.started == 2 and process.pid not in (None, first)


def trajectory_frame(id: str, count: int, names: list[str]) -> str:
    """A ``/joint_trajectory`` publish of ``count`` points, 10 ms apart."""
    points = [
        {
            "positions": [0.1] * len(names),
            "time_from_start": {"sec": k // 100, "nanosec": k % 100 * 10**7},
        }
        for k in range(1, count + 1)
    ]
    msg = {"joint_names": names, "points": points}
    return json.dumps({"op": "publish", "id": id, "topic": "/joint_trajectory", "msg": msg})


def refusal(ws: ClientConnection, frame: str) -> tuple[str, str]:
    """The status a refused frame gets, and the error on the client's reply topic."""
    ws.send(frame)
    status = reply = None
    while status is None or reply is None:
        answer = json.loads(ws.recv(timeout=WAIT_S))
        if answer["op"] == "status":
            status = answer["msg"]
        elif answer["op"] == "publish" and answer["topic"] == "/c2rviz/reply":
            reply = answer["msg"]["data"]
    return status, reply


def test_a_large_trajectory_naming_a_joint_the_arm_lacks_is_refused_as_it_decodes(
    world_server: WorldServer, monkeypatch
) -> None:
    """Its points never come back to the loop: the decoding process sends its outline
    (names, count, duration), and the client hears, byte for byte, what a small frame
    naming the same joint hears; the world notes each as refused, with its points' count."""
    kept: list[object] = []
    real = messages.remember
    monkeypatch.setattr(messages, "remember", lambda m, r: (kept.append(r), real(m, r))[1])
    names = ["joint_s", "hand"]
    large = trajectory_frame("p", 3000, names)
    assert len(large) > DECODE_ON_LOOP_BYTES
    with connect(world_server.url, open_timeout=WAIT_S, max_size=None) as ws:
        ws.send(json.dumps({"op": "subscribe", "topic": "/c2rviz/reply"}))
        small = refusal(ws, trajectory_frame("p", 2, names))
        assert refusal(ws, large) == small
    expected = "publish /joint_trajectory: joint_names[1]: 'hand' is not a joint of motoman_sia20d"
    assert small[0].startswith(expected) and small[1] == f"error: {small[0]}"
    assert kept == [messages.TrajectoryOutline(("joint_s", "hand"), 3000, 30.0)]
    notes = [(n.line, n.accepted) for n in world_server.notes_of("/joint_trajectory")]
    assert notes == [
        ("/joint_trajectory 2 points, 0.02 s", False),
        ("/joint_trajectory 3000 points, 30 s", False),
    ]


def test_an_outline_whose_joints_the_arm_has_is_refused(world_server: WorldServer) -> None:
    """An outline is only made for a trajectory naming a joint its robot lacks; were the
    robot's joints others by the time it is served, it is still refused, never played."""
    from c2rviz.errors import C2rvizError
    from c2rviz.session import Session

    outline = messages.TrajectoryOutline(("joint_s",), 2, 1.0)

    async def serve() -> str:
        try:
            await joint_trajectory(Session(world_server.services, "test"), outline)
        except C2rvizError as error:
            return str(error)
        return "taken"

    assert "send it again" in world_server.run(serve())
    assert world_server.notes_of("/joint_trajectory")[-1].accepted is False
