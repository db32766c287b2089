"""What the rosbridge server needs from the rest of c2rviz: the ``Bridge`` protocol.

The server (``server.RosbridgeServer``) owns the wire: frames, ids, statuses,
throttling, queues and limits. Everything about the robot is behind a
``Bridge``: which topics and services exist, delivering the messages of a
topic, and taking a client's messages and service calls through the session
path (checked, guarded, recorded) like any other source of commands.

Names the server passes are absolute (``/joint_states``) and types are in the
ROS 2 spelling (``sensor_msgs/msg/JointState``). Messages are JSON-ready dicts
in the ROS 2 message shape (``messages`` reads the ones c2rviz takes).
"""

from __future__ import annotations

from collections.abc import Awaitable, Callable, Mapping, Sequence
from typing import Any, Protocol

__all__ = ["Bridge", "Deliver"]

Deliver = Callable[[dict[str, Any]], None]
"""Hands one message of a topic to the server; returns at once."""


class Bridge(Protocol):
    """c2rviz as rosbridge sees it; the server calls these on its event loop."""

    def topics(self) -> Sequence[tuple[str, str]]:
        """Every topic, published or taken: ``(name, type)``: ``("/tf", "tf2_msgs/msg/TFMessage")``.

        Either type spelling will do; the list may change between calls.
        """
        ...

    def services(self) -> Sequence[tuple[str, str]]:
        """Every service besides rosapi's: ``(name, type)``, e.g. ``("/c2rviz/command", ...)``."""
        ...

    def params(self) -> Mapping[str, object]:
        """Parameters by name for ``/rosapi/get_param``: ``robot_description`` (URDF text)."""
        ...

    def opened(self, source: str) -> None:
        """A client connected: ``source`` (``rosbridge 127.0.0.1:50412``) names it from now on."""
        ...

    def closed(self, source: str) -> None:
        """The client ``source`` is gone (its subscriptions are already stopped)."""
        ...

    def hang_up_with(self, hang_up: Callable[[str], None]) -> None:
        """From now on ``hang_up(source)`` closes the client ``source``'s connection (it may
        connect again): the bridge calls it when a client must go (``fault disconnect``)."""
        ...

    def subscribe(self, topic: str, deliver: Deliver) -> object:
        """Start calling ``deliver(msg)`` for each message of ``topic``; return a handle.

        ``deliver`` is cheap and never blocks: it puts the message in the
        subscriber's outbox (latest wins) and returns. Call it on the server's
        event loop thread if you can; from another thread it is handed over.
        The server encodes a message once for all subscribers, later than the
        call, so a delivered dict must not be changed afterwards. A latched
        topic (``/tf_static``, ``/robot_description``) delivers its last
        message at once, inside this call.

        Raises:
            C2rvizError: ``topic`` is not one c2rviz publishes.
        """
        ...

    def snapshot(self, topic: str) -> dict[str, Any] | None:
        """The whole state of ``topic`` now, for a subscriber that missed some of its messages.

        The server asks when a slow subscriber's outbox pushed a message out. Return
        None where each message is whole (a joint state: the latest is enough); a
        topic of changes (markers added and deleted) returns one message that
        replaces all before it.
        """
        ...

    def unsubscribe(self, handle: object) -> None:
        """Stop the deliveries of ``handle`` (from ``subscribe``); idempotent."""
        ...

    def publish(self, source: str, topic: str, msg: dict[str, Any]) -> Awaitable[None]:
        """Take one message a client published on ``topic``.

        Args:
            source: Who sent it (``rosbridge 127.0.0.1:50412``), for the session's records.
            topic: The absolute topic name.
            msg: The message as the client sent it, not yet checked against its type;
                a large one of a type c2rviz reads (``messages.read_ahead``) was read
                as it was decoded, and comes as a stand-in that its reader takes.

        Returns:
            An awaitable that ends once the message is taken (a move started),
            not when its motion ends; the connection's next request waits for it.

        Raises:
            C2rvizError: To refuse it (an unknown topic, a message that does not
                fit its type, a limit or the guard); its text goes to the client.
        """
        ...

    def call_service(
        self, source: str, service: str, args: dict[str, Any]
    ) -> Awaitable[dict[str, Any]]:
        """Answer one service call; the result is the response's ``values``.

        Raises:
            C2rvizError: The call is refused; the client gets a ``service_response``
                with ``result: false`` and this text, and a ``status`` error.
        """
        ...
