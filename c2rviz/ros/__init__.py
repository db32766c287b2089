"""The ROS door: ROS 2 messages as dicts, our robot as TF, and rosbag2 bags out and in.

No ROS installation is needed: messages are plain dicts (``messages``), encoded
to CDR by ``cdr``; bags are written and read through ``rosbags`` (rosbag2 with
MCAP storage out; rosbag2 folders, bare ``.mcap``/``.db3`` files and ROS 1
``.bag`` files in). Nothing here uses asyncio or the world: the recorder and
the player drive these pieces.

- ``messages``: builders of JointState, TFMessage and String dicts, stamps,
  namespaces and frame prefixes, and MarkerArray dicts (markers and workcell
  objects);
- ``cdr``: ``CdrEncoder``, dict -> CDR bytes, compiled once per type, and
  ``JointStateDecoder``, a serialized JointState read quickly;
- ``tf_tree``: ``TfTree``, a robot's joint states and transforms as
  robot_state_publisher gives them;
- ``bag_writer``: ``BagWriter``, one rosbag2 MCAP bag being written, and
  ``BagRobot``, one robot's topics in it; ``bag_repair``: ending a bag whose
  writing stopped half-way;
- ``bag_reader``: ``JointStateBag``, a bag's JointState samples, checked, streamed
  (``cdr`` decodes them);
- ``errors``: the door's errors (all ``C2rvizError``).

Importing the package is cheap (a rosbridge door needs ``messages`` alone); the
heavy parts (Pinocchio, rosbags) load when first named.
"""

from importlib import import_module
from typing import Any

from .errors import (
    AmbiguousTopic,
    BadSample,
    BagCorrupted,
    BagError,
    DescriptionError,
    EmptySpan,
    MessageError,
    MissingJoint,
    NoJointStateTopic,
    NotABag,
    RosError,
    StampsBackwards,
    UnknownTopic,
)

__all__ = [
    "AmbiguousTopic",
    "BadSample",
    "BagCorrupted",
    "BagError",
    "BagRobot",
    "BagWriter",
    "DescriptionError",
    "EmptySpan",
    "JointStateBag",
    "MessageError",
    "MissingJoint",
    "NoJointStateTopic",
    "NotABag",
    "RosError",
    "StampsBackwards",
    "TfTree",
    "UnknownTopic",
]

_HOME = {
    "BagRobot": "bag_writer",
    "BagWriter": "bag_writer",
    "JointStateBag": "bag_reader",
    "TfTree": "tf_tree",
}


def __getattr__(name: str) -> Any:
    if name in _HOME:
        return getattr(import_module(f".{_HOME[name]}", __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
