"""rosbridge v2: ROS web tools and scripts (roslibpy, roslibjs) talk to c2rviz.

``protocol`` reads and writes the JSON frames, ``messages`` checks the ROS 2
messages c2rviz takes, ``rosapi`` answers the discovery services,
``msg_definitions`` holds the ``.msg`` texts, all pure; ``server`` is the
asyncio websocket server (``policy`` its guard, ``outbox`` its per-subscriber
queues, ``connection`` one client), and ``bridge`` the protocol the rest of
c2rviz implements for it.

``robot_bridge.RobotBridge`` is that ``Bridge`` for the world: ``robot_topics``
names each robot's topics and frames and builds its messages (``c2rviz.ros``'s
shapes), ``world_feed`` publishes the world's effects at the frame rate through
``topic_hub``, ``command_lines`` runs each client's text lines through its
``Session``, and ``joint_inputs`` takes joint commands and trajectories.
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
from .robot_bridge import RobotBridge
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
    "RobotBridge",
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
