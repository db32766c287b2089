"""The requests of rosbridge v2, one frozen dataclass per ``op`` (client to server).

``protocol.parse_frame`` makes them from a frame's text. Names (``topic``,
``service``) are as the client spelled them: the server answers in that
spelling (roslibpy matches on it) and hands ``resolve_name`` of it to c2rviz.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, TypeAlias

FrameId: TypeAlias = "str | int | None"
"""A request's ``id``: a string or an integer, echoed in the answers to it."""


@dataclass(frozen=True)
class Subscribe:
    """Client to server: send me each message of ``topic`` (as ``publish`` frames).

    ``type`` is normalised (``pkg/msg/Name``) or None when not given;
    ``throttle_rate_ms`` is the least time between two frames [ms];
    ``queue_length`` how many messages wait while throttled (0: only the newest).
    """

    id: FrameId
    topic: str
    type: str | None = None
    throttle_rate_ms: int = 0
    queue_length: int = 0
    compression: str = "none"


@dataclass(frozen=True)
class Unsubscribe:
    """Client to server: stop subscription ``id`` of ``topic`` (all of them if no id)."""

    id: FrameId
    topic: str


@dataclass(frozen=True)
class Advertise:
    """Client to server: I will publish ``topic`` with messages of ``type``."""

    id: FrameId
    topic: str
    type: str


@dataclass(frozen=True)
class Unadvertise:
    """Client to server: I no longer publish ``topic``."""

    id: FrameId
    topic: str


@dataclass(frozen=True)
class Publish:
    """Client to server: one message on ``topic`` (a JSON object, checked by its taker)."""

    id: FrameId
    topic: str
    msg: dict[str, Any]


@dataclass(frozen=True)
class CallService:
    """Client to server: call ``service`` with ``args``; answered by ``service_response``."""

    id: FrameId
    service: str
    args: dict[str, Any]
    type: str | None = None


@dataclass(frozen=True)
class SetLevel:
    """Client to server: send me statuses up to ``level`` (one of ``LEVELS``)."""

    id: FrameId
    level: str


@dataclass(frozen=True)
class Unsupported:
    """Client to server: an op rosbridge v2 defines that c2rviz does not serve."""

    id: FrameId
    op: str


Op: TypeAlias = (
    Subscribe
    | Unsubscribe
    | Advertise
    | Unadvertise
    | Publish
    | CallService
    | SetLevel
    | Unsupported
)


_OP_NAMES: dict[type, str] = {
    Subscribe: "subscribe",
    Unsubscribe: "unsubscribe",
    Advertise: "advertise",
    Unadvertise: "unadvertise",
    Publish: "publish",
    CallService: "call_service",
    SetLevel: "set_level",
}


def op_name(op: Op) -> str:
    """The ``op`` field of the frame ``op`` was read from."""
    return op.op if isinstance(op, Unsupported) else _OP_NAMES[type(op)]


def resolve_name(name: str) -> str:
    """The absolute ROS name for a topic or service name as a client spelled it.

    c2rviz's node lives in the root namespace, so ``joint_states`` is
    ``/joint_states``. The name must already have passed ``parse_frame``.
    """
    return name if name.startswith("/") else "/" + name
