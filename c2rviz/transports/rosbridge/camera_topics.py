"""The logical cameras on rosbridge: each camera's topic, and its frames on ``/tf``.

Each camera NAME publishes ``/c2rviz/cameras/NAME`` (``geometry_msgs/msg/PoseArray``): its
header's ``frame_id`` is the camera's frame ``cameras/NAME`` and its poses are the seen
parts' in that frame, in the order ``camera NAME`` replies them (an empty array: it sees
nothing). A PoseArray is in rosbags' ROS 2 stores and RViz draws it; it carries no
names, so the same report goes on ``/tf`` too: the camera's frame (a child of the
world's frame, as the parts' frames are) and a frame ``cameras/NAME/PART`` per seen part,
a child of the camera's, so a TF listener knows which part is where.

Reports come at the camera's rate on the world's clock (``observers.camera_feed``), while
anyone subscribes to a camera's topic; a new subscriber gets what the camera sees now at
once. A camera's topic exists from the moment the camera is placed (topics are never
taken back: a removed camera's topic publishes nothing more).
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import partial

import pinocchio as pin

from ...observers.camera_feed import CAMERA_TOPIC, POSE_ARRAY, CameraFeed, camera_items, pose_array
from ...ros.messages import Msg, tf_message, transforms
from ...world.cameras import Camera, Seen
from ...world.observer import Observer
from ...world.world import World, sight
from .topic_hub import TopicHub

__all__ = ["CameraTopics"]


class CameraTopics(Observer):
    """Publishes every camera of the world (add it to the world's observers)."""

    def __init__(
        self, world: World, hub: TopicHub, parent: str, to_parent: pin.SE3, tf_topic: str
    ) -> None:
        """Set up.

        Args:
            world: The world whose cameras it publishes.
            hub: Where the messages go.
            parent: The frame cameras hang from on ``/tf`` (the parts' parent).
            to_parent: Takes a world pose into ``parent``.
            tf_topic: ``/tf``.
        """
        self.world, self.hub = world, hub
        self.parent, self.to_parent, self.tf_topic = parent, to_parent, tf_topic
        self.topics: dict[str, str] = {}
        self._readers = 0
        self.feed = CameraFeed(world, self._report)
        self.on_cameras(world.cameras.all())

    def published(self) -> list[tuple[str, str]]:
        """``(topic, type)`` of every camera's topic."""
        return [(topic, POSE_ARRAY) for topic in self.topics.values()]

    def close(self) -> None:
        self.feed.close()

    def on_cameras(self, cameras: Sequence[Camera]) -> None:
        for camera in cameras:
            if camera.name not in self.topics:
                topic = self.topics[camera.name] = CAMERA_TOPIC.format(name=camera.name)
                self.hub.add_topic(topic, partial(self._now, camera.name), watcher=self._reading)
        self.feed.sync(self._readers > 0)

    def on_command(self, source: str, line: str, accepted: bool) -> None:
        self.feed.wake()

    def _reading(self, reading: bool) -> None:
        self._readers += 1 if reading else -1
        self.feed.sync(self._readers > 0)

    def _now(self, name: str) -> Msg | None:
        if name not in self.world.cameras:
            return None
        return pose_array(self.world.clock.now(), name, sight(self.world, name))

    def _report(self, name: str, t: float, seen: Sequence[Seen]) -> None:
        topic = self.topics.get(name)
        if topic is not None and self.hub.wanted(topic):
            self.hub.publish(topic, pose_array(t, name, seen))
        if self.hub.wanted(self.tf_topic):
            camera = self.world.cameras.get(name)
            items = camera_items(self.parent, self.to_parent, camera, seen)
            self.hub.publish(self.tf_topic, tf_message(transforms(t, items)))
