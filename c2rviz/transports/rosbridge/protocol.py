"""rosbridge v2 frames: one JSON text frame in, one operation out (pure, no I/O).

``parse_frame`` turns the text of one websocket frame into a frozen dataclass
per operation (``Subscribe``, ``Publish``, ``CallService``, ...) or raises
``RosbridgeError``, which carries the request's ``id`` and ``op`` when they
could be read, so the server can answer with a ``status`` naming the problem.
The JSON is strict: ``NaN``, ``Infinity`` and numbers too large for a float
are refused, as a browser's ``JSON.parse`` would. Operations rosbridge v2
defines that c2rviz does not serve (actions, service servers, fragments) parse
to ``Unsupported``; anything else is an unknown op.

The builders (``publish``, ``service_response``, ``status``) make the frames a
server sends, as compact JSON text (roslibpy cannot read binary frames).
Reference: RobotWebTools/rosbridge_suite, ``ROSBRIDGE_PROTOCOL.md``.
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Mapping
from typing import Any

from ...errors import C2rvizError
from .messages import TypeNameError, normalize_type
from .ops import (
    Advertise,
    CallService,
    FrameId,
    Op,
    Publish,
    SetLevel,
    Subscribe,
    Unadvertise,
    Unsubscribe,
    Unsupported,
)

LEVELS = ("none", "error", "warning", "info")
"""Status levels, least verbose first; a client sees statuses up to its level."""
COMPRESSIONS = ("none", "png", "cbor", "cbor-raw")
"""The ``compression`` values rosbridge v2 names for a subscription."""
SUPPORTED_OPS = (
    "advertise",
    "call_service",
    "publish",
    "set_level",
    "subscribe",
    "unadvertise",
    "unsubscribe",
)
UNSUPPORTED_OPS = (
    "action_feedback",
    "action_result",
    "advertise_action",
    "advertise_service",
    "auth",
    "cancel_action_goal",
    "fragment",
    "png",
    "send_action_goal",
    "service_response",
    "status",
    "unadvertise_action",
    "unadvertise_service",
)
INT32_MAX = 2**31 - 1
_NAME = re.compile(r"/?[A-Za-z_][A-Za-z0-9_]*(/[A-Za-z_][A-Za-z0-9_]*)*")
_COMPACT = (",", ":")


class RosbridgeError(C2rvizError):
    """A frame that is not a request c2rviz can serve; answered with a ``status``.

    Attributes:
        id: The request's ``id`` when it could be read, else None.
        op: The request's ``op`` when it could be read, else None.
        service: For a ``call_service``, its service name when it could be read.
        problem: What was wrong, without the op.
    """

    def __init__(
        self, problem: str, id: FrameId = None, op: str | None = None, service: str | None = None
    ) -> None:
        self.id, self.op, self.service, self.problem = id, op, service, problem
        super().__init__(f"{op}: {problem}" if op else problem)


def _refuse_constant(token: str) -> float:
    raise ValueError(f"{token} is not a JSON number")


def _strict_float(text: str) -> float:
    value = float(text)
    if not math.isfinite(value):
        raise ValueError(f"number {text[:40]} is too large for a float")
    return value


def _loads(text: str) -> object:
    try:
        return json.loads(text, parse_constant=_refuse_constant, parse_float=_strict_float)
    except RecursionError:
        raise RosbridgeError("frame is nested too deeply to read") from None
    except ValueError as error:  # JSONDecodeError, or one of ours, or an over-long integer
        raise RosbridgeError(f"frame is not valid JSON ({error})") from None


class _Fields:
    """Reads the fields of one request, raising ``RosbridgeError`` that names them."""

    def __init__(self, frame: Mapping[str, Any], op: str, id: FrameId) -> None:
        self.frame, self.op, self.id = frame, op, id

    def error(self, problem: str) -> RosbridgeError:
        service = self.frame.get("service") if self.op == "call_service" else None
        return RosbridgeError(
            problem, self.id, self.op, service if isinstance(service, str) else None
        )

    def name(self, field: str) -> str:
        value = self.frame.get(field)
        if value is None:
            raise self.error(f"{field} is missing")
        if not isinstance(value, str):
            raise self.error(f"{field} must be a string, not {_kind(value)}")
        if not _NAME.fullmatch(value):
            raise self.error(
                f"{field} {_quoted(value)} is not a ROS name ('/'-separated parts of letters, "
                "digits and '_', none starting with a digit)"
            )
        return value

    def type(self, field: str, required: bool) -> str | None:
        value = self.frame.get(field)
        if value is None and not required:
            return None
        if value is None:
            raise self.error(f"{field} is missing")
        if not isinstance(value, str):
            raise self.error(f"{field} must be a string, not {_kind(value)}")
        try:
            return normalize_type(value)
        except TypeNameError as error:
            raise self.error(str(error)) from None

    def count(self, field: str) -> int:
        value = self.frame.get(field, 0)
        if value is None:
            return 0
        if isinstance(value, bool) or not isinstance(value, int):
            raise self.error(f"{field} must be an integer, not {_kind(value)}")
        if not 0 <= value <= INT32_MAX:
            raise self.error(f"{field} {value} is outside 0..{INT32_MAX}")
        return value

    def choice(self, field: str, choices: tuple[str, ...], default: str | None) -> str:
        value = self.frame.get(field, default)
        if value is None:
            raise self.error(f"{field} is missing (one of: {', '.join(choices)})")
        if not isinstance(value, str) or value not in choices:
            shown = _quoted(value) if isinstance(value, str) else _kind(value)
            raise self.error(f"{field} {shown} is not one of: {', '.join(choices)}")
        return value

    def object(self, field: str, required: bool) -> dict[str, Any]:
        value = self.frame.get(field)
        if value is None and not required:
            return {}
        if value is None:
            raise self.error(f"{field} is missing")
        if isinstance(value, list) and not value and not required:
            return {}  # rosbridge allows args: [] for a service without arguments
        if not isinstance(value, dict):
            raise self.error(f"{field} must be a JSON object, not {_kind(value)}")
        return value


def _kind(value: object) -> str:
    names = {bool: "a boolean", int: "an integer", float: "a number", str: "a string"}
    names |= {list: "an array", dict: "an object", type(None): "null"}
    return names.get(type(value), type(value).__name__)


def _quoted(text: str, limit: int = 40) -> str:
    return repr(text if len(text) <= limit else text[:limit] + "...")


def parse_frame(text: str) -> Op:
    """Read one rosbridge request from the text of one frame.

    Args:
        text: The frame's text, one JSON object.

    Returns:
        The operation, a frozen dataclass. Fields rosbridge defines that c2rviz
        does not use (``fragment_size``, ``latch``, ``queue_size``) are ignored.

    Raises:
        RosbridgeError: Not JSON, not an object, no or an unknown ``op``, a
            missing or mistyped field; ``id`` and ``op`` are set when readable.
    """
    frame = _loads(text)
    if not isinstance(frame, dict):
        raise RosbridgeError(f"frame must be a JSON object, not {_kind(frame)}")
    raw_id = frame.get("id")
    id: FrameId = (
        raw_id if isinstance(raw_id, (str, int)) and not isinstance(raw_id, bool) else None
    )
    op = frame.get("op")
    if op is None:
        raise RosbridgeError(f"op is missing (one of: {', '.join(SUPPORTED_OPS)})", id)
    if not isinstance(op, str):
        raise RosbridgeError(f"op must be a string, not {_kind(op)}", id)
    if op not in SUPPORTED_OPS and op not in UNSUPPORTED_OPS:
        raise RosbridgeError(
            f"unknown op {_quoted(op)} (c2rviz serves: {', '.join(SUPPORTED_OPS)})", id
        )
    fields = _Fields(frame, op, id)
    if raw_id is not None and id is None:
        raise fields.error(f"id must be a string or an integer, not {_kind(raw_id)}")
    if op in UNSUPPORTED_OPS:
        return Unsupported(id, op)
    if op == "subscribe":
        return Subscribe(
            id,
            fields.name("topic"),
            fields.type("type", required=False),
            fields.count("throttle_rate"),
            fields.count("queue_length"),
            fields.choice("compression", COMPRESSIONS, "none"),
        )
    if op == "unsubscribe":
        return Unsubscribe(id, fields.name("topic"))
    if op == "advertise":
        topic = fields.name("topic")
        type_name = fields.type("type", required=True)
        assert type_name is not None
        return Advertise(id, topic, type_name)
    if op == "unadvertise":
        return Unadvertise(id, fields.name("topic"))
    if op == "publish":
        return Publish(id, fields.name("topic"), fields.object("msg", required=True))
    if op == "call_service":
        service = fields.name("service")
        return CallService(
            id, service, fields.object("args", required=False), _service_type(fields)
        )
    return SetLevel(id, fields.choice("level", LEVELS, None))


def _service_type(fields: _Fields) -> str | None:
    value = fields.frame.get("type")
    if value is None:
        return None
    if not isinstance(value, str):
        raise fields.error(f"type must be a string, not {_kind(value)}")
    try:
        return normalize_type(value, kind="srv")
    except TypeNameError as error:
        raise fields.error(str(error)) from None


def _dumps(frame: Mapping[str, Any]) -> str:
    return json.dumps(frame, separators=_COMPACT, ensure_ascii=False, allow_nan=False)


def publish(topic: str, msg: Mapping[str, Any]) -> str:
    """The frame carrying one message of a subscription.

    Args:
        topic: The topic as the subscriber spelled it (roslibpy matches on it).
        msg: The message; JSON types only, finite numbers.

    Raises:
        ValueError: ``msg`` holds NaN, an infinity or a value JSON cannot hold.
    """
    return _dumps({"op": "publish", "topic": topic, "msg": msg})


def service_response(
    id: FrameId, service: str, values: Mapping[str, Any] | str, result: bool
) -> str:
    """The answer to a ``call_service``: its ``values`` (or an error text) and ``result``."""
    frame: dict[str, Any] = {"op": "service_response", "service": service}
    if id is not None:
        frame["id"] = id
    frame["values"] = values
    frame["result"] = result
    return _dumps(frame)


def status(level: str, msg: str, id: FrameId = None) -> str:
    """A ``status`` frame at ``level`` (``error``, ``warning``, ``info``) about request ``id``."""
    frame: dict[str, Any] = {"op": "status", "level": level, "msg": msg}
    if id is not None:
        frame["id"] = id
    return _dumps(frame)
