"""The rosbridge frame parser and builders: tables of good and bad frames."""

from __future__ import annotations

import json

import pytest

from c2rviz.errors import C2rvizError
from c2rviz.transports.rosbridge.ops import op_name, resolve_name
from c2rviz.transports.rosbridge.protocol import (
    UNSUPPORTED_OPS,
    Advertise,
    CallService,
    Publish,
    RosbridgeError,
    SetLevel,
    Subscribe,
    Unadvertise,
    Unsubscribe,
    Unsupported,
    parse_frame,
    publish,
    service_response,
    status,
)

GOOD = [
    (  # what roslibpy's Topic.subscribe sends
        '{"op": "subscribe", "id": "subscribe:/joint_states:1", "type": "sensor_msgs/JointState",'
        ' "topic": "/joint_states", "compression": "none", "throttle_rate": 0, "queue_length": 0}',
        Subscribe("subscribe:/joint_states:1", "/joint_states", "sensor_msgs/msg/JointState"),
    ),
    (
        '{"op": "subscribe", "topic": "tf", "throttle_rate": 100, "queue_length": 5}',
        Subscribe(None, "tf", None, 100, 5),
    ),
    ('{"op": "unsubscribe", "id": 7, "topic": "/tf"}', Unsubscribe(7, "/tf")),
    (  # roslibpy's Topic.advertise
        '{"op": "advertise", "id": "advertise:/c2rviz/command:2", "type": "std_msgs/String",'
        ' "topic": "/c2rviz/command", "latch": false, "queue_size": 100}',
        Advertise("advertise:/c2rviz/command:2", "/c2rviz/command", "std_msgs/msg/String"),
    ),
    ('{"op": "unadvertise", "topic": "/x"}', Unadvertise(None, "/x")),
    (
        '{"op": "publish", "id": "p", "topic": "/c2rviz/command", "msg": {"data": "home"},'
        ' "latch": false}',
        Publish("p", "/c2rviz/command", {"data": "home"}),
    ),
    (  # roslibpy's Service.call: no type
        '{"op": "call_service", "id": "call_service:/rosapi/topics:3",'
        ' "service": "/rosapi/topics", "args": {}}',
        CallService("call_service:/rosapi/topics:3", "/rosapi/topics", {}),
    ),
    (  # roslibjs 1.x: a type, and args may be an empty list
        '{"op": "call_service", "service": "/c2rviz/command", "type": "c2rviz_msgs/Command",'
        ' "args": []}',
        CallService(None, "/c2rviz/command", {}, "c2rviz_msgs/srv/Command"),
    ),
    ('{"op": "call_service", "service": "/rosapi/nodes"}', CallService(None, "/rosapi/nodes", {})),
    ('{"op": "set_level", "level": "warning", "id": "l"}', SetLevel("l", "warning")),
    (
        '{"op": "advertise_service", "service": "/s", "type": "a/B"}',
        Unsupported(None, "advertise_service"),
    ),
    (
        '{"op": "fragment", "id": "f", "data": "{", "num": 0, "total": 2}',
        Unsupported("f", "fragment"),
    ),
]


@pytest.mark.parametrize(("text", "op"), GOOD, ids=[json.loads(t)["op"] for t, _ in GOOD])
def test_a_good_frame_parses(text: str, op: object) -> None:
    assert parse_frame(text) == op


BAD = [
    ("", None, None, "frame is not valid JSON"),
    ("{'op': 'subscribe'}", None, None, "frame is not valid JSON"),
    (
        '{"op": "publish", "topic": "/x", "msg": {"data": NaN}}',
        None,
        None,
        "NaN is not a JSON number",
    ),
    ('{"op": "publish", "topic": "/x", "msg": {"v": -Infinity}}', None, None, "-Infinity"),
    ('{"op": "publish", "topic": "/x", "msg": {"v": 1e999}}', None, None, "too large for a float"),
    ("[" * 100_000 + "]" * 100_000, None, None, "nested too deeply"),
    ('"subscribe"', None, None, "frame must be a JSON object, not a string"),
    ("null", None, None, "frame must be a JSON object, not null"),
    ('{"id": "a"}', "a", None, "op is missing (one of: advertise, call_service"),
    ('{"op": 5, "id": "a"}', "a", None, "op must be a string, not an integer"),
    ('{"op": "jump", "id": 4}', 4, None, "unknown op 'jump' (c2rviz serves: advertise"),
    ('{"op": "subscribe", "id": 1.5, "topic": "/x"}', None, "subscribe", "id must be a string or"),
    ('{"op": "subscribe", "id": true, "topic": "/x"}', None, "subscribe", "not a boolean"),
    ('{"op": "subscribe", "id": "s"}', "s", "subscribe", "topic is missing"),
    ('{"op": "subscribe", "id": "s", "topic": 3}', "s", "subscribe", "topic must be a string"),
    (
        '{"op": "subscribe", "id": "s", "topic": "/a b"}',
        "s",
        "subscribe",
        "'/a b' is not a ROS name",
    ),
    ('{"op": "subscribe", "id": "s", "topic": "/a//b"}', "s", "subscribe", "is not a ROS name"),
    ('{"op": "subscribe", "id": "s", "topic": "/1a"}', "s", "subscribe", "is not a ROS name"),
    ('{"op": "subscribe", "id": "s", "topic": "/a/"}', "s", "subscribe", "is not a ROS name"),
    (
        '{"op": "subscribe", "id": "s", "topic": "/a", "type": "JointState"}',
        "s",
        "subscribe",
        "type 'JointState' is not a msg type name",
    ),
    (
        '{"op": "subscribe", "id": "s", "topic": "/a", "type": "a/srv/B"}',
        "s",
        "subscribe",
        "is a srv type, not a msg type",
    ),
    (
        '{"op": "subscribe", "id": "s", "topic": "/a", "throttle_rate": -1}',
        "s",
        "subscribe",
        "throttle_rate -1 is outside 0..2147483647",
    ),
    (
        '{"op": "subscribe", "id": "s", "topic": "/a", "throttle_rate": 1.5}',
        "s",
        "subscribe",
        "throttle_rate must be an integer, not a number",
    ),
    (
        '{"op": "subscribe", "id": "s", "topic": "/a", "queue_length": "5"}',
        "s",
        "subscribe",
        "queue_length must be an integer, not a string",
    ),
    (
        '{"op": "subscribe", "id": "s", "topic": "/a", "compression": "zip"}',
        "s",
        "subscribe",
        "compression 'zip' is not one of: none, png, cbor, cbor-raw",
    ),
    ('{"op": "unsubscribe", "id": "u"}', "u", "unsubscribe", "topic is missing"),
    ('{"op": "advertise", "id": "a", "topic": "/a"}', "a", "advertise", "type is missing"),
    ('{"op": "publish", "id": "p", "topic": "/a"}', "p", "publish", "msg is missing"),
    (
        '{"op": "publish", "id": "p", "topic": "/a", "msg": [1]}',
        "p",
        "publish",
        "msg must be a JSON object, not an array",
    ),
    ('{"op": "call_service", "id": "c"}', "c", "call_service", "service is missing"),
    (
        '{"op": "call_service", "id": "c", "service": "/s", "args": [1]}',
        "c",
        "call_service",
        "args must be a JSON object",
    ),
    (
        '{"op": "call_service", "id": "c", "service": "/s", "type": 5}',
        "c",
        "call_service",
        "type must be a string",
    ),
    ('{"op": "set_level", "id": "l"}', "l", "set_level", "level is missing (one of: none, error"),
]


@pytest.mark.parametrize(("text", "id", "op", "problem"), BAD, ids=[b[3] for b in BAD])
def test_a_bad_frame_is_refused_with_its_id_and_op(
    text: str, id: object, op: str | None, problem: str
) -> None:
    with pytest.raises(RosbridgeError) as refused:
        parse_frame(text)
    assert isinstance(refused.value, C2rvizError)
    assert (refused.value.id, refused.value.op) == (id, op)
    assert problem in str(refused.value)
    if op is not None:
        assert str(refused.value).startswith(f"{op}: ")


def test_a_refused_call_service_keeps_its_service_for_the_response() -> None:
    with pytest.raises(RosbridgeError) as refused:
        parse_frame('{"op": "call_service", "id": 1, "service": "/s", "args": 3}')
    assert refused.value.service == "/s"


@pytest.mark.parametrize("op", UNSUPPORTED_OPS)
def test_every_other_rosbridge_op_is_read_as_unsupported(op: str) -> None:
    parsed = parse_frame(json.dumps({"op": op, "id": "x"}))
    assert parsed == Unsupported("x", op) and op_name(parsed) == op


def test_op_names_are_the_frames_ops() -> None:
    for text, op in GOOD:
        assert op_name(op) == json.loads(text)["op"]  # type: ignore[arg-type]


def test_names_resolve_in_the_root_namespace() -> None:
    assert resolve_name("joint_states") == "/joint_states"
    assert resolve_name("/c2rviz/command") == "/c2rviz/command"


def test_the_builders_make_compact_json() -> None:
    assert publish("/c", {"data": "é"}) == '{"op":"publish","topic":"/c","msg":{"data":"é"}}'
    assert json.loads(service_response("call:1", "/s", {"ok": True}, True)) == {
        "op": "service_response",
        "service": "/s",
        "id": "call:1",
        "values": {"ok": True},
        "result": True,
    }
    assert "id" not in json.loads(service_response(None, "/s", "no", False))
    assert json.loads(status("error", "bad", 3)) == {
        "op": "status",
        "level": "error",
        "msg": "bad",
        "id": 3,
    }
    assert "id" not in json.loads(status("warning", "w"))


def test_publish_refuses_nan() -> None:
    with pytest.raises(ValueError):
        publish("/c", {"v": float("nan")})
