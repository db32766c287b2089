"""The errors of the ROS door: bad messages, and bags that cannot be played.

Each one is a ``C2rvizError`` whose ``str()`` is one line that says what was
wrong and, where there is a finite set, what is valid.
"""

from __future__ import annotations

from collections.abc import Sequence

from ..errors import C2rvizError

_LISTED = 12  # names listed in a message before "and N more"


def listing(names: Sequence[str], limit: int = _LISTED) -> str:
    """``a, b, c`` (at most ``limit`` names, then ``and N more``), or ``none``."""
    if not names:
        return "none"
    shown = ", ".join(names[:limit])
    if len(names) > limit:
        shown += f" and {len(names) - limit} more"
    return shown


class RosError(C2rvizError):
    """Root of the ROS door's errors."""


class MessageError(RosError):
    """A message dict that does not fit its ROS type, or a builder given bad values."""


class DescriptionError(RosError):
    """A robot description whose joint tree cannot be read for TF."""


class BagError(RosError):
    """A bag that cannot be read or played; ``path`` names it."""

    def __init__(self, path: str, problem: str) -> None:
        self.path = path
        self.problem = problem
        super().__init__(f"{path}: {problem}")


class NotABag(BagError):
    """The path is not a rosbag2 folder, an .mcap, a .db3 or a ROS 1 .bag."""


class BagCorrupted(BagError):
    """A bag file that is truncated or damaged."""


class NoJointStateTopic(BagError):
    """A bag without a ``sensor_msgs/JointState`` topic; lists what it has."""

    def __init__(self, path: str, topics: Sequence[tuple[str, str]]) -> None:
        self.topics = tuple(topics)
        has = listing([f"{name} ({msgtype})" for name, msgtype in topics])
        super().__init__(path, f"has no sensor_msgs/JointState topic; its topics: {has}")


class AmbiguousTopic(BagError):
    """Several JointState topics and none chosen."""

    def __init__(self, path: str, topics: Sequence[str]) -> None:
        self.topics = tuple(topics)
        super().__init__(
            path, f"has {len(topics)} JointState topics, choose one with --topic: {listing(topics)}"
        )


class UnknownTopic(BagError):
    """A chosen topic that is not a JointState topic of the bag."""

    def __init__(self, path: str, topic: str, topics: Sequence[str]) -> None:
        self.topic = topic
        self.topics = tuple(topics)
        super().__init__(
            path, f"has no JointState topic {topic!r}; its JointState topics: {listing(topics)}"
        )


class EmptySpan(BagError):
    """No JointState message in the span asked for."""


class MissingJoint(BagError):
    """A chain joint that a JointState message does not name."""

    def __init__(self, path: str, joint: str, t_s: float, names: Sequence[str]) -> None:
        self.joint = joint
        self.t_s = t_s
        self.names = tuple(names)
        super().__init__(
            path,
            f"chain joint {joint!r} is missing from the JointState at {t_s:.6f} s "
            f"(it names: {listing(names)})",
        )


class BadSample(BagError):
    """A JointState message with a value that cannot be played (NaN, inf, wrong length)."""


class StampsBackwards(BagError):
    """A header stamp earlier than the one before it on the topic."""

    def __init__(self, path: str, t_s: float, stamp_s: float, previous_s: float) -> None:
        self.t_s = t_s
        self.stamp_s = stamp_s
        self.previous_s = previous_s
        super().__init__(
            path,
            f"JointState stamps go backwards at {t_s:.6f} s: stamp {stamp_s:.9f} s "
            f"after {previous_s:.9f} s",
        )
