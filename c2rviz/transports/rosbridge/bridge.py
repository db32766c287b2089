"""What the rosbridge server needs from the rest of c2rviz: the ``Bridge`` protocol.

The server (``server.RosbridgeServer``) owns the wire: frames, ids, statuses,
throttling, queues and limits. Everything about the robot is behind a
``Bridge``: which topics and services exist, delivering the messages of a
topic, and taking a client's messages and service calls through the session
path (checked, guarded, recorded) like any other source of commands.

Names the server passes are absolute (``/joint_states``) and types are in the
ROS 2 spelling (``sensor_msgs/msg/JointState``). Messages are JSON-ready dicts
in the ROS 2 message shape (``messages`` reads the ones c2rviz takes).

Who subscribes to what c2rviz publishes, and what a new subscriber gets at once:
``TopicHub`` keeps, per topic, the ``deliver`` callbacks the server registered (one per
client subscription, see ``Bridge.subscribe``). ``publish`` hands one message to every
subscriber of a topic (the same dict: the server encodes it once for all). A topic may
have a *greeting*: a function whose message a new subscriber gets at once, inside
``subscribe``. A latched topic's greeting is its last message (``/tf_static``,
``/robot_description``); others give the state now (``/joint_states``: where the arm
is, so a dashboard opened beside a resting arm shows it). A topic may also have a
*watcher*, told when its first subscriber comes and its last goes (``/c2rviz/events``
listens to the watch hub only while someone reads it). A topic of *changes* (markers
added and deleted) hands its greeting, the whole state, to a subscriber that missed
some of its messages (``snapshot``).
"""

from __future__ import annotations

import logging
from collections.abc import Awaitable, Callable, Collection, Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Protocol

from ...errors import C2rvizError

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

    def trajectory_joints(self) -> Mapping[str, Collection[str]]:
        """The joint names a trajectory may name, by the absolute name of each topic that
        takes trajectories (``[NS]/joint_trajectory``: its robot's chain joints). A large
        one naming another is refused as it is decoded: only its outline
        (``messages.TrajectoryOutline``) comes to ``publish``, never its points."""
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
                as it was decoded, and comes as a stand-in that its reader (or, for a
                trajectory refused there, ``messages.outline``) takes.

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


# The TopicHub: who subscribes to what c2rviz publishes.

log = logging.getLogger("c2rviz.rosbridge")

Greeting = Callable[[], "dict[str, Any] | None"]
"""The message a new subscriber gets at once, or None for none yet."""
Watcher = Callable[[bool], None]
"""Told True when a topic gets its first subscriber, False when its last one goes."""


@dataclass(frozen=True, eq=False)
class _Handle:
    topic: str


class TopicHub:
    """The subscribers of every published topic."""

    def __init__(self) -> None:
        self._subscribers: dict[str, dict[_Handle, Deliver]] = {}
        self._greetings: dict[str, Greeting] = {}
        self._watchers: dict[str, Watcher] = {}
        self._changes: set[str] = set()

    def add_topic(
        self,
        topic: str,
        greeting: Greeting | None = None,
        watcher: Watcher | None = None,
        changes: bool = False,
    ) -> None:
        """Publish ``topic`` from now on (with what a new subscriber gets, and who is told).

        ``changes``: its messages are changes (markers added, deleted), so a subscriber
        that missed one is brought up to date with the greeting (``snapshot``).
        """
        self._subscribers.setdefault(topic, {})
        if changes:
            self._changes.add(topic)
        if greeting is not None:
            self._greetings[topic] = greeting
        if watcher is not None:
            self._watchers[topic] = watcher

    def latch(self, topic: str, msg: dict[str, Any]) -> None:
        """``msg`` is ``topic``'s message from now on for every new subscriber; send it now."""
        self._greetings[topic] = lambda: msg
        self.publish(topic, msg)

    def subscribe(self, topic: str, deliver: Deliver) -> object:
        """Deliver ``topic``'s messages to ``deliver``; its greeting first, inside this call.

        Raises:
            C2rvizError: ``topic`` is not published here.
        """
        subscribers = self._subscribers.get(topic)
        if subscribers is None:
            raise C2rvizError(f"{topic} is not published by c2rviz (it takes messages there)")
        handle = _Handle(topic)
        first = not subscribers
        subscribers[handle] = deliver
        if first and topic in self._watchers:
            self._watchers[topic](True)
        greeting = self._greetings.get(topic)
        if greeting is not None:
            msg = greeting()
            if msg is not None:
                deliver(msg)
        return handle

    def unsubscribe(self, handle: object) -> None:
        """Stop a subscription (from ``subscribe``); idempotent."""
        if not isinstance(handle, _Handle):
            return
        subscribers = self._subscribers.get(handle.topic, {})
        if subscribers.pop(handle, None) is not None and not subscribers:
            watcher = self._watchers.get(handle.topic)
            if watcher is not None:
                watcher(False)

    def snapshot(self, topic: str) -> dict[str, Any] | None:
        """The greeting of a topic of changes (its whole state now); None for the others."""
        greeting = self._greetings.get(topic) if topic in self._changes else None
        return greeting() if greeting is not None else None

    def wanted(self, topic: str) -> bool:
        """Whether anyone subscribes to ``topic`` now (else its messages need not be made)."""
        return bool(self._subscribers.get(topic))

    def count(self, topic: str) -> int:
        """Subscriptions to ``topic`` now."""
        return len(self._subscribers.get(topic, ()))

    def publish(self, topic: str, msg: dict[str, Any]) -> None:
        """Hand ``msg`` to every subscriber of ``topic`` (none: nothing happens)."""
        for deliver in list(self._subscribers.get(topic, {}).values()):
            try:
                deliver(msg)
            except Exception:  # one subscriber's failure must not cost the others theirs
                log.exception("rosbridge: delivering a message of %s failed", topic)
