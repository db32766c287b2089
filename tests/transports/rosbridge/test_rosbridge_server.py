"""The rosbridge server through a raw websockets client: answers, statuses, guards, limits."""

from __future__ import annotations

import json
import socket
from collections.abc import Iterator
from typing import Any

import pytest
from rosbridge_support import WAIT_S, CounterBridge, ServerThread
from websockets.exceptions import ConnectionClosed, InvalidStatus
from websockets.sync.client import connect
from websockets.sync.connection import Connection as ClientConnection

from c2rviz.transports.rosbridge import RosbridgePolicy


def receive(ws: ClientConnection) -> dict[str, Any]:
    frame = ws.recv(timeout=WAIT_S)
    assert isinstance(frame, str), "the server sends JSON text frames only"
    answer = json.loads(frame)
    assert isinstance(answer, dict)
    return answer


def ask(ws: ClientConnection, frame: dict[str, Any] | str | bytes) -> dict[str, Any]:
    ws.send(frame if isinstance(frame, (str, bytes)) else json.dumps(frame))
    return receive(ws)


def command(ws: ClientConnection, line: str, id: str = "probe") -> dict[str, Any]:
    request = {"op": "call_service", "id": id, "service": "/c2rviz/command"}
    return ask(ws, request | {"args": {"command": line}})


def subscribe(ws: ClientConnection, server: ServerThread, topic: str, **fields: Any) -> None:
    """Subscribe and wait until the bridge has the subscription."""
    ws.send(json.dumps({"op": "subscribe", "topic": topic} | fields))
    assert server.bridge.subscribed.get(timeout=WAIT_S) == "/" + topic.lstrip("/")


@pytest.fixture
def client(rosbridge: ServerThread) -> Iterator[ClientConnection]:
    with connect(rosbridge.url, open_timeout=WAIT_S) as ws:
        yield ws


BAD_FRAMES = [
    ("not json", None, "frame is not valid JSON"),
    ("[1, 2]", None, "frame must be a JSON object, not an array"),
    ('{"op": "publish", "id": "n", "topic": "/inbox", "msg": {"data": NaN}}', None, "NaN"),
    ('{"id": 3}', 3, "op is missing"),
    ('{"op": "fly", "id": "f"}', "f", "unknown op 'fly'"),
    ('{"op": "subscribe", "id": "s1"}', "s1", "subscribe: topic is missing"),
    ('{"op": "subscribe", "id": "s2", "topic": "/nope"}', "s2", "no topic /nope (topics: "),
    (
        '{"op": "subscribe", "id": "s3", "topic": "/counter", "type": "sensor_msgs/JointState"}',
        "s3",
        "/counter has type std_msgs/msg/String, not sensor_msgs/msg/JointState",
    ),
    (
        '{"op": "subscribe", "id": "s4", "topic": "/counter", "compression": "cbor"}',
        "s4",
        "compression 'cbor' is not served",
    ),
    (
        '{"op": "subscribe", "id": "s5", "topic": "/inbox"}',
        "s5",
        "subscribe /inbox: /inbox is not published here",
    ),
    (
        '{"op": "publish", "id": "p1", "topic": "/inbox", "msg": {"data": 5}}',
        "p1",
        "publish /inbox: std_msgs/msg/String: data must be a string",
    ),
    (
        '{"op": "publish", "id": "p2", "topic": "/joint_command",'
        ' "msg": {"name": ["a", "b"], "position": [1.0]}}',
        "p2",
        "position has 1 values for 2 joints",
    ),
    (
        '{"op": "publish", "id": "p3", "topic": "/counter", "msg": {"data": "x"}}',
        "p3",
        "c2rviz does not take /counter",
    ),
    (
        '{"op": "advertise", "id": "a1", "topic": "/inbox", "type": "sensor_msgs/JointState"}',
        "a1",
        "advertise: /inbox has type std_msgs/msg/String, not sensor_msgs/msg/JointState",
    ),
    (
        '{"op": "advertise_service", "id": "as", "service": "/x", "type": "a/B"}',
        "as",
        "advertise_service: is not served by c2rviz",
    ),
    ('{"op": "set_level", "id": "l", "level": "loud"}', "l", "level 'loud' is not one of"),
]


@pytest.mark.parametrize(("frame", "id", "text"), BAD_FRAMES, ids=[t for _, _, t in BAD_FRAMES])
def test_a_bad_frame_is_answered_with_a_status_and_the_connection_goes_on(
    client: ClientConnection, frame: str, id: object, text: str
) -> None:
    answer = ask(client, frame)
    assert answer["op"] == "status" and answer["level"] == "error"
    assert answer.get("id") == id
    assert text in answer["msg"]
    assert command(client, "home")["values"] == {"reply": "did home", "ok": True}


def test_a_binary_frame_is_answered_with_a_status(client: ClientConnection) -> None:
    answer = ask(client, json.dumps({"op": "subscribe", "topic": "/counter"}).encode())
    assert answer["op"] == "status" and "binary frames" in answer["msg"]


def test_a_service_call_comes_back_with_its_id(client: ClientConnection) -> None:
    answer = command(client, "joints 0 0 0", id="call:7")
    assert answer == {
        "op": "service_response",
        "service": "/c2rviz/command",
        "id": "call:7",
        "values": {"reply": "did joints 0 0 0", "ok": True},
        "result": True,
    }


@pytest.mark.parametrize(
    ("request_", "text"),
    [
        ({"service": "/c2rviz/command", "args": {"command": "fail now"}}, "refused on purpose"),
        ({"service": "/c2rviz/command", "args": {"line": "x"}}, "has no field 'line'"),
        ({"service": "/nope"}, "no service /nope (services: /c2rviz/command, /rosapi/"),
        ({"service": "/c2rviz/command", "args": 5}, "args must be a JSON object"),
        ({"service": "/rosapi/get_param", "args": {"name": "x"}}, "no parameter 'x'"),
    ],
    ids=["refused", "bad-args", "unknown-service", "args-not-object", "unknown-param"],
)
def test_a_refused_service_call_gets_result_false_with_its_id_and_a_status(
    client: ClientConnection, request_: dict[str, Any], text: str
) -> None:
    response = ask(client, {"op": "call_service", "id": 41} | request_)
    assert response["op"] == "service_response" and response["id"] == 41
    assert response["result"] is False and text in response["values"]
    status = receive(client)
    assert status["op"] == "status" and status["id"] == 41 and text in status["msg"]


def test_rosapi_is_answered_by_the_server(client: ClientConnection) -> None:
    call = {"op": "call_service", "id": "t", "service": "/rosapi/topics_and_raw_types"}
    values = ask(client, call)["values"]
    assert values["topics"] == [t for t, _ in CounterBridge.TOPICS]
    assert values["types"][1] == "std_msgs/msg/String"  # the bridge said std_msgs/String
    assert values["typedefs_full_text"][0] == "string data\n"


def test_set_level_chooses_which_statuses_come(client: ClientConnection) -> None:
    unsubscribe = {"op": "unsubscribe", "id": "u", "topic": "/counter"}
    client.send(json.dumps(unsubscribe))  # a warning: not sent at the default level
    assert command(client, "one")["op"] == "service_response"
    client.send(json.dumps({"op": "set_level", "level": "warning"}))
    answer = ask(client, unsubscribe)
    assert answer["level"] == "warning" and "no subscription to /counter" in answer["msg"]
    client.send(json.dumps({"op": "set_level", "level": "none"}))
    client.send("not json")  # an error, but the client asked for none
    assert command(client, "two")["op"] == "service_response"


def test_subscribe_receives_the_topic_in_the_spelling_asked(
    rosbridge: ServerThread, client: ClientConnection
) -> None:
    subscribe(client, rosbridge, "counter", id="c")
    rosbridge.call(rosbridge.bridge.tick)
    assert receive(client) == {"op": "publish", "topic": "counter", "msg": {"data": "1"}}


def test_a_delivery_from_another_thread_arrives(
    rosbridge: ServerThread, client: ClientConnection
) -> None:
    subscribe(client, rosbridge, "/counter")
    rosbridge.bridge.tick()  # on this thread, not the server's loop
    assert receive(client)["msg"] == {"data": "1"}


def test_a_latched_topic_comes_at_once(rosbridge: ServerThread, client: ClientConnection) -> None:
    client.send(json.dumps({"op": "subscribe", "topic": "/latched", "type": "std_msgs/String"}))
    assert receive(client)["msg"] == {"data": "latched hello"}


def test_latest_wins_when_messages_come_faster_than_they_go(
    rosbridge: ServerThread, client: ClientConnection
) -> None:
    subscribe(client, rosbridge, "/counter", throttle_rate=1)  # a throttle: latest wins
    rosbridge.call(rosbridge.bridge.tick, 6)  # six messages before the outbox can send one
    assert receive(client)["msg"] == {"data": "6"}
    assert rosbridge.server.stats["thinned"] == 5


def test_a_topic_of_changes_sends_its_whole_state_after_a_thinning(
    rosbridge: ServerThread, client: ClientConnection
) -> None:
    rosbridge.bridge.changes = True  # /counter's messages are changes now (as markers are)
    subscribe(client, rosbridge, "/counter", throttle_rate=1)
    rosbridge.call(rosbridge.bridge.tick, 6)  # six before the outbox can send one: 5 pushed out
    assert receive(client)["msg"] == {"data": "all 6"}  # the whole state, not the last change
    rosbridge.call(rosbridge.bridge.tick)
    assert receive(client)["msg"] == {"data": "7"}  # then changes again
    assert rosbridge.server.stats["thinned"] == 5


def test_queue_length_keeps_the_newest_few(
    rosbridge: ServerThread, client: ClientConnection
) -> None:
    subscribe(client, rosbridge, "/counter", throttle_rate=1, queue_length=3)
    rosbridge.call(rosbridge.bridge.tick, 5)
    assert [receive(client)["msg"]["data"] for _ in range(3)] == ["3", "4", "5"]
    assert rosbridge.server.stats["thinned"] == 2


def test_throttle_rate_holds_messages_back_and_keeps_the_latest(
    rosbridge: ServerThread, client: ClientConnection
) -> None:
    subscribe(client, rosbridge, "/counter", throttle_rate=60_000)
    rosbridge.call(rosbridge.bridge.tick)
    assert receive(client)["msg"] == {"data": "1"}
    rosbridge.call(rosbridge.bridge.tick, 3)
    # unthrottled, "4" would go before this call's frame even arrives
    assert command(client, "after")["op"] == "service_response"
    assert rosbridge.server.stats["thinned"] == 2


def test_a_short_throttle_sends_the_latest_after_it(
    rosbridge: ServerThread, client: ClientConnection
) -> None:
    subscribe(client, rosbridge, "/counter", throttle_rate=200)
    rosbridge.call(rosbridge.bridge.tick)
    assert receive(client)["msg"] == {"data": "1"}
    rosbridge.call(rosbridge.bridge.tick, 3)
    assert receive(client)["msg"] == {"data": "4"}


def test_two_subscriptions_to_one_topic_get_one_frame_per_message(
    rosbridge: ServerThread, client: ClientConnection
) -> None:
    subscribe(client, rosbridge, "/counter", id="a")
    client.send(json.dumps({"op": "subscribe", "id": "b", "topic": "/counter"}))
    assert command(client, "sync")["op"] == "service_response"  # "b" is in
    rosbridge.call(rosbridge.bridge.tick)
    assert receive(client)["msg"] == {"data": "1"}
    assert command(client, "next")["op"] == "service_response"  # no second copy of "1"
    client.send(json.dumps({"op": "unsubscribe", "id": "a", "topic": "/counter"}))
    rosbridge.call(rosbridge.bridge.tick)
    assert receive(client)["msg"] == {"data": "2"}
    client.send(json.dumps({"op": "unsubscribe", "id": "b", "topic": "/counter"}))
    assert rosbridge.bridge.unsubscribed.get(timeout=WAIT_S) == "/counter"


def test_a_closed_connection_unsubscribes(rosbridge: ServerThread) -> None:
    with connect(rosbridge.url, open_timeout=WAIT_S) as ws:
        subscribe(ws, rosbridge, "/counter")
    assert rosbridge.bridge.unsubscribed.get(timeout=WAIT_S) == "/counter"


@pytest.mark.parametrize("policy", [RosbridgePolicy(max_subscriptions=3)])
def test_the_subscriptions_of_a_connection_are_capped(
    rosbridge: ServerThread, client: ClientConnection
) -> None:
    for id in "abc":
        client.send(json.dumps({"op": "subscribe", "id": id, "topic": "/counter"}))
    answer = ask(client, {"op": "subscribe", "id": "d", "topic": "/latched"})
    assert answer["op"] == "status" and answer["id"] == "d"
    assert "too many subscriptions on this connection (limit 3)" in answer["msg"]
    client.send(json.dumps({"op": "subscribe", "id": "a", "topic": "/counter"}))  # a change
    client.send(json.dumps({"op": "unsubscribe", "id": "c", "topic": "/counter"}))
    client.send(json.dumps({"op": "subscribe", "id": "d", "topic": "/latched"}))
    assert receive(client)["msg"] == {"data": "latched hello"}


@pytest.mark.parametrize("policy", [RosbridgePolicy(max_connections=2)])
def test_one_connection_too_many_is_closed_with_1013(rosbridge: ServerThread) -> None:
    with connect(rosbridge.url) as first, connect(rosbridge.url) as second:
        assert command(first, "a")["result"] and command(second, "b")["result"]
        with connect(rosbridge.url) as third, pytest.raises(ConnectionClosed) as closed:
            third.recv(timeout=WAIT_S)
        assert closed.value.rcvd is not None and closed.value.rcvd.code == 1013
        assert "too many rosbridge connections (limit 2)" in closed.value.rcvd.reason
    assert rosbridge.server.stats["refused connections"] == 1


@pytest.mark.parametrize("policy", [RosbridgePolicy(max_frame_bytes=4096)])
def test_an_oversize_frame_closes_with_1009_and_others_go_on(
    rosbridge: ServerThread, client: ClientConnection
) -> None:
    with connect(rosbridge.url) as other:
        big = {"op": "publish", "topic": "/inbox", "msg": {"data": "x" * 5000}}
        client.send(json.dumps(big))
        with pytest.raises(ConnectionClosed) as closed:
            client.recv(timeout=WAIT_S)
        assert closed.value.rcvd is not None and closed.value.rcvd.code == 1009
        assert command(other, "still here")["result"] is True


def test_a_subscriber_that_does_not_read_is_thinned_and_others_go_on(
    rosbridge: ServerThread, client: ClientConnection
) -> None:
    # it reads one frame and stops; its close cannot be answered through full buffers: give up soon
    with connect(rosbridge.url, max_queue=1, close_timeout=0.5) as stuck:
        subscribe(stuck, rosbridge, "/counter")
        ticks = 0
        while rosbridge.server.stats["thinned"] == 0:  # until the socket buffers are full
            rosbridge.call(rosbridge.bridge.tick, 1, 65_536)
            ticks += 1
            assert ticks < 20_000, "the outbox never thinned"
        assert command(client, "meanwhile")["result"] is True


ORIGINS = [
    (None, True),
    ("http://localhost:8080", True),
    ("https://127.0.0.1", True),
    ("http://[::1]:3000", True),
    ("https://dashboard.example.org", True),
    ("https://evil.example.com", False),
    ("null", False),
]


@pytest.mark.parametrize("policy", [RosbridgePolicy(("https://dashboard.example.org",))])
@pytest.mark.parametrize(("origin", "allowed"), ORIGINS, ids=[str(o) for o, _ in ORIGINS])
def test_a_browser_from_a_foreign_origin_is_refused_with_403(
    rosbridge: ServerThread, origin: str | None, allowed: bool
) -> None:
    headers = {"Origin": origin} if origin else {}
    if allowed:
        with connect(rosbridge.url, additional_headers=headers) as ws:
            assert command(ws, "hi")["result"] is True
        return
    with pytest.raises(InvalidStatus) as refused:
        connect(rosbridge.url, additional_headers=headers)
    assert refused.value.response.status_code == 403
    assert rosbridge.server.stats["refused origin"] == 1


def test_two_origin_headers_are_refused(rosbridge: ServerThread) -> None:
    headers = [("Origin", "http://localhost"), ("Origin", "https://evil.example.com")]
    with pytest.raises(InvalidStatus) as refused:
        connect(rosbridge.url, additional_headers=headers)
    assert refused.value.response.status_code == 403


@pytest.mark.parametrize("policy", [RosbridgePolicy(token="s3cret")])
def test_with_a_token_a_connection_needs_it(rosbridge: ServerThread) -> None:
    for url in (rosbridge.url, rosbridge.url + "?token=wrong"):
        with pytest.raises(InvalidStatus) as refused:
            connect(url)
        assert refused.value.response.status_code == 403
    with connect(rosbridge.url + "?token=s3cret") as ws:
        assert command(ws, "hi")["result"] is True


def test_stop_gives_up_a_service_call_that_waits(bridge: CounterBridge) -> None:
    server = ServerThread(bridge, RosbridgePolicy())
    server.call(bridge.release.clear)
    with connect(server.url) as ws:
        ws.send(
            json.dumps(
                {"op": "call_service", "service": "/c2rviz/command", "args": {"command": "hold"}}
            )
        )
        assert bridge.calls.get(timeout=WAIT_S) == "hold"
        server.stop()  # within WAIT_S, or it raises
        with pytest.raises(ConnectionClosed) as closed:
            ws.recv(timeout=WAIT_S)
        assert closed.value.rcvd is not None and closed.value.rcvd.code == 1001


def test_the_port_is_free_after_stop(bridge: CounterBridge) -> None:
    server = ServerThread(bridge, RosbridgePolicy())
    ws = connect(server.url)
    server.stop()
    with pytest.raises(ConnectionClosed) as closed:
        ws.recv(timeout=WAIT_S)
    assert closed.value.rcvd is not None and closed.value.rcvd.code == 1001
    ws.close()
    with socket.socket() as probe:  # as a new server would listen: SO_REUSEADDR, as asyncio does
        probe.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        probe.bind(("127.0.0.1", server.port))
        probe.listen()


def test_the_bridge_hears_each_client_come_and_go(rosbridge: ServerThread) -> None:
    with connect(rosbridge.url) as ws:
        assert command(ws, "hi")["result"] is True
        kind, source = rosbridge.bridge.sources.get(timeout=WAIT_S)
        assert kind == "opened" and source.startswith("rosbridge 127.0.0.1:")
    assert rosbridge.bridge.sources.get(timeout=WAIT_S) == ("closed", source)


def test_a_client_leaving_gives_up_its_waiting_request(rosbridge: ServerThread) -> None:
    rosbridge.call(rosbridge.bridge.release.clear)  # "hold" waits until released: never here
    with connect(rosbridge.url) as ws:
        ws.send(
            json.dumps(
                {"op": "call_service", "service": "/c2rviz/command", "args": {"command": "hold"}}
            )
        )
        assert rosbridge.bridge.calls.get(timeout=WAIT_S) == "hold"
    assert rosbridge.bridge.sources.get(timeout=WAIT_S)[0] == "opened"
    assert rosbridge.bridge.sources.get(timeout=WAIT_S)[0] == "closed"  # without the release
    assert rosbridge.server.connections == 0
