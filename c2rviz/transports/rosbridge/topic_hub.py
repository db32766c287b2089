"""Who subscribes to what c2rviz publishes, and what a new subscriber gets at once.

``TopicHub`` keeps, per topic, the ``deliver`` callbacks the rosbridge server
registered (one per client subscription, see ``bridge.Bridge.subscribe``).
``publish`` hands one message to every subscriber of a topic (the same dict:
the server encodes it once for all). A topic may have a *greeting*: a function
whose message a new subscriber gets at once, inside ``subscribe``. A latched
topic's greeting is its last message (``/tf_static``, ``/robot_description``);
others give the state now (``/joint_states``: where the arm is, so a dashboard
opened beside a resting arm shows it). A topic may also have a *watcher*, told
when its first subscriber comes and its last goes (``/c2rviz/events`` listens
to the watch hub only while someone reads it). A topic of *changes* (markers
added and deleted) hands its greeting, the whole state, to a subscriber that
missed some of its messages (``snapshot``).
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from ...errors import C2rvizError
from .bridge import Deliver

__all__ = ["Greeting", "TopicHub", "Watcher"]

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
