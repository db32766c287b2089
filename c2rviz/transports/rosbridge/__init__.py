"""rosbridge v2: ROS web tools and scripts (roslibpy, roslibjs, Foxglove) talk to c2rviz.

``protocol`` reads and writes the JSON frames, ``messages`` checks the ROS 2
messages c2rviz takes, ``rosapi`` answers the discovery services,
``msg_definitions`` holds the ``.msg`` texts, all pure; ``server`` is the
asyncio websocket server (``policy`` its guard, ``outbox`` its per-subscriber
queues), and ``bridge`` the protocol the rest of c2rviz implements for it.
"""

from .bridge import Bridge, Deliver
from .messages import (
    COMMAND_SERVICE_TYPE,
    JointPositions,
    JointTrajectory,
    MessageError,
    TrajectoryPoint,
    TypeNameError,
    command_request,
    command_response,
    joint_positions,
    joint_trajectory,
    normalize_type,
    same_type,
    string_data,
)
from .policy import PolicyError, RosbridgePolicy
from .protocol import RosbridgeError, parse_frame
from .rosapi import Graph, RosapiError
from .server import RosbridgeServer

__all__ = [
    "COMMAND_SERVICE_TYPE",
    "Bridge",
    "Deliver",
    "Graph",
    "JointPositions",
    "JointTrajectory",
    "MessageError",
    "PolicyError",
    "RosapiError",
    "RosbridgeError",
    "RosbridgePolicy",
    "RosbridgeServer",
    "TrajectoryPoint",
    "TypeNameError",
    "command_request",
    "command_response",
    "joint_positions",
    "joint_trajectory",
    "normalize_type",
    "parse_frame",
    "same_type",
    "string_data",
]
