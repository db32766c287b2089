"""The world's effects as ROS messages: an ``Observer`` that feeds the ``TopicHub``.

Joints, markers and workcell objects change as often as commands come (a flood
of ``joints`` lines changes the arm a hundred thousand times a second), so they
are published at the world's frame rate at most: a change marks its robot, and
one flush per frame (``world.frame_s``, on the world's clock) sends the latest
state, latest wins. A flush comes at once when the last one is at least
``FLUSH_SLACK`` of a frame old, so an arm moving frame by frame is published
as it moves, without waiting another frame. Each flush sends, for the robots
that changed and only for topics someone reads:

* ``[NS]/joint_states``: stamped with the world's clock time of the change;
* ``/tf``: every robot's moving joints and every part's frame ``parts/NAME``
  (``observers.bag_topics``; one message holds them all, so a slow subscriber that
  keeps only the latest loses no robot), stamped likewise;
* ``[NS]/visualization_marker_array``: markers added (and those pushed out past
  ``MAX_MARKERS`` deleted; all deleted after a ``clear``, or when more went than
  half of those left, then all sent again), and the workcell objects as a whole
  when they changed.

``/diagnostics`` carries every robot's faults whenever they change (``topics.diagnostics``);
``/tf_static`` and ``[NS]/robot_description`` are latched from the start;
events (``watch``'s texts) go out on ``[NS]/c2rviz/events`` as they happen.
New subscribers of joints, TF and markers get the state now at once; a marker
subscriber too slow to take every change gets that whole state again instead
of the changes it missed (a topic of changes: ``TopicHub.snapshot``).
"""

from __future__ import annotations

from collections import deque
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from functools import partial

import pinocchio as pin

from ...collision.workcell import WorkcellObject
from ...observers.bag_topics import part_items
from ...observers.watch import WatchHub
from ...ros.messages import Msg, marker_array, string, tf_message, transforms
from ...world.clock import Timer
from ...world.observer import MAX_MARKERS, Observer
from ...world.parts import Part
from ...world.state import Marker
from ...world.world import World
from .bridge import TopicHub
from .topics import DIAGNOSTICS_TOPIC, WORLD_FRAME, RobotTopics, diagnostics

FLUSH_SLACK = 0.9
"""A flush comes at once when the previous one is this many frames old (timer jitter)."""
TF_TOPIC, TF_STATIC_TOPIC = "/tf", "/tf_static"


@dataclass(eq=False)
class _Robot:
    """What the feed keeps of one robot between flushes."""

    topics: RobotTopics
    pending: tuple[tuple[float, ...], float] | None = None  # (q, t) not yet published
    markers: deque[tuple[int, Marker]] = field(default_factory=lambda: deque(maxlen=MAX_MARKERS))
    next_id: int = 0
    sent: set[int] = field(default_factory=set)  # marker ids the subscribers have
    cleared: bool = False
    markers_changed: bool = False
    objects: Sequence[WorkcellObject] = ()
    objects_changed: bool = False


class WorldFeed(Observer):
    """Publishes the world's robots on their topics (add it to the world's observers)."""

    def __init__(
        self,
        world: World,
        hub: TopicHub,
        robots: Mapping[str, RobotTopics],
        watch: WatchHub,
    ) -> None:
        """Register every published topic with ``hub`` and latch the static ones.

        Args:
            world: The world whose effects it is given.
            hub: Where the messages go.
            robots: Each robot's topics, by its name in the world.
            watch: The watch hub, listened to while anyone reads an events topic.
        """
        self.world, self.hub, self.watch = world, hub, watch
        self.robots = {name: _Robot(topics) for name, topics in robots.items()}
        self._timer: Timer | None = None
        self._last_flush = -float("inf")
        self._readers = 0  # events topics read now
        self._parts_at: float | None = None  # when parts last moved, not yet published
        now = world.clock.now()
        statics: list[Msg] = []
        for name, feed in self.robots.items():
            state, topics = world.state(name), feed.topics
            feed.markers.extend((k, m) for k, m in enumerate(state.markers))
            feed.next_id = len(state.markers)
            model = world.contacts.models.get(name)  # built only if it has objects or checks
            feed.objects = model.object_list() if model is not None else ()
            hub.add_topic(topics.joint_states, partial(self._joints_now, topics))
            hub.add_topic(topics.markers, partial(self._markers_now, feed), changes=True)
            hub.add_topic(topics.events, watcher=self._events_read)
            hub.add_topic(topics.reply)
            hub.add_topic(topics.robot_description)
            hub.latch(topics.robot_description, string(state.robot.source.xml))
            statics.extend(topics.statics(now, state.origin))
        hub.add_topic(TF_TOPIC, self._tf_now)
        hub.add_topic(TF_STATIC_TOPIC)
        hub.latch(TF_STATIC_TOPIC, tf_message(statics))
        hub.add_topic(DIAGNOSTICS_TOPIC, self._diagnostics_now)

    def close(self) -> None:
        """Stop: no more flushes, no more listening."""
        if self._timer is not None:
            self._timer.cancel()
            self._timer = None
        if self._readers:
            self._readers = 0
            self.watch.unlisten(self._event)

    # What a new subscriber gets at once.

    def _joints_now(self, topics: RobotTopics) -> Msg:
        q = self.world.faults.sensed(topics.name, self.world.state(topics.name).q)
        return topics.joint_state(q, self.world.clock.now())

    def _diagnostics_now(self) -> Msg:
        faults = self.world.faults
        return diagnostics(self.world.clock.now(), faults.robots, faults.origin)

    def _tf_now(self) -> Msg:
        return self._tf(self.world.clock.now())

    def _markers_now(self, feed: _Robot) -> Msg:
        topics, t = feed.topics, self.world.clock.now()
        msgs = [topics.markers_cleared(t)]
        msgs.extend(topics.marker(t, k, m) for k, m in feed.markers)
        msgs.extend(topics.objects(t, feed.objects))
        return marker_array(msgs)

    def _tf(self, t: float) -> Msg:
        """Every robot's moving joints and every part as shown now, stamped ``t`` [s]."""
        items: list[tuple[str, str, Sequence[float], Sequence[float]]] = []
        for name, feed in self.robots.items():
            items.extend(feed.topics.moving(self.world.state(name).q))
        first = next(iter(self.robots), None)
        if first is not None and self.world.parts.parts:
            frame = self.robots[first].topics.marker_frame
            to_parent = self.world.state(first).origin.inverse()
            to_parent = pin.SE3.Identity() if frame == WORLD_FRAME else to_parent
            items.extend(part_items(frame, to_parent, self.world.parts.parts.all()))
        return tf_message(transforms(t, items))

    def on_parts(self, parts: Sequence[Part], t: float) -> None:
        self._parts_at = t
        self._schedule()

    # The world's effects.

    def on_joints(self, robot: str, q: Sequence[float], t: float) -> None:
        feed = self.robots.get(robot)
        if feed is not None:
            feed.pending = (q if isinstance(q, tuple) else tuple(q), t)
            self._schedule()

    def on_marker(self, robot: str, marker: Marker) -> None:
        feed = self.robots.get(robot)
        if feed is not None:
            feed.markers.append((feed.next_id, marker))
            feed.next_id += 1
            feed.markers_changed = True
            self._schedule()

    def on_clear_markers(self, robot: str) -> None:
        feed = self.robots.get(robot)
        if feed is not None:
            feed.markers.clear()
            feed.cleared = feed.markers_changed = True
            self._schedule()

    def on_fault(self, robot: str, text: str) -> None:
        if self.hub.wanted(DIAGNOSTICS_TOPIC):  # every robot's status, as it is now
            self.hub.publish(DIAGNOSTICS_TOPIC, self._diagnostics_now())

    def on_objects(self, robot: str, objects: Sequence[WorkcellObject]) -> None:
        feed = self.robots.get(robot)
        if feed is not None:
            feed.objects = tuple(objects)
            feed.objects_changed = True
            self._schedule()

    # Events, while anyone reads them.

    def _events_read(self, reading: bool) -> None:
        self._readers += 1 if reading else -1
        if reading and self._readers == 1:
            self.watch.listen(self._event)
        elif not reading and self._readers == 0:
            self.watch.unlisten(self._event)

    def _event(self, robot: str | None, text: str) -> None:
        msg = string(text)
        for name, feed in self.robots.items():
            if robot is None or robot == name:
                self.hub.publish(feed.topics.events, msg)

    # The flush.

    def _schedule(self) -> None:
        if self._timer is not None:
            return
        clock = self.world.clock
        due = self._last_flush + FLUSH_SLACK * self.world.frame_s
        self._timer = clock.call_at(max(due, clock.now()), self._flush)

    def _flush(self) -> None:
        """Publish what changed since the last flush (latest wins)."""
        self._timer = None
        self._last_flush = self.world.clock.now()
        hub = self.hub
        moved_at = None
        for feed in self.robots.values():
            if feed.pending is not None:
                q, t = feed.pending
                feed.pending = None
                moved_at = t if moved_at is None else max(moved_at, t)
                topics = feed.topics
                if hub.wanted(topics.joint_states):
                    q = self.world.faults.sensed(topics.name, q)  # encoder noise, if on
                    hub.publish(topics.joint_states, topics.joint_state(q, t))
            if feed.markers_changed or feed.objects_changed:
                self._flush_markers(feed)
        if self._parts_at is not None:
            moved_at = self._parts_at if moved_at is None else max(moved_at, self._parts_at)
            self._parts_at = None
        if moved_at is not None and hub.wanted(TF_TOPIC):
            hub.publish(TF_TOPIC, self._tf(moved_at))

    def _flush_markers(self, feed: _Robot) -> None:
        topics, t = feed.topics, self.world.clock.now()
        wanted = self.hub.wanted(topics.markers)
        msgs: list[Msg] = []
        if feed.markers_changed:
            shown = {k for k, _ in feed.markers}
            if wanted:
                gone = feed.sent - shown
                if feed.cleared or len(gone) > len(shown) // 2:  # a flood: start afresh
                    msgs.append(topics.markers_cleared(t))
                    feed.sent.clear()
                    gone.clear()
                msgs.extend(topics.marker_gone(t, k) for k in sorted(gone))
                msgs.extend(topics.marker(t, k, m) for k, m in feed.markers if k not in feed.sent)
            feed.sent = shown
        if feed.objects_changed and wanted:
            msgs.extend(topics.objects(t, feed.objects))
        feed.cleared = feed.markers_changed = feed.objects_changed = False
        if msgs:
            self.hub.publish(topics.markers, marker_array(msgs))
