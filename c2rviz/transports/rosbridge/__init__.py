"""rosbridge v2: ROS web tools and scripts (roslibpy, roslibjs) talk to c2rviz.

``protocol`` reads and writes the JSON frames (``ops`` the requests), ``messages``
checks the ROS 2 messages c2rviz takes, ``rosapi`` answers the discovery services and
holds the ``.msg`` texts, all pure; ``server`` is the asyncio websocket server
(``policy`` its guard, ``outbox`` its per-subscriber queues, ``connection`` one client),
and ``bridge`` the protocol the rest of c2rviz implements for it (and the
``TopicHub`` of its subscribers).

``robot_bridge.RobotBridge`` is that ``Bridge`` for the world: ``topics`` names each
robot's topics and frames and builds its messages (``c2rviz.ros``'s shapes), the
cameras' and the diagnostics; ``world_feed`` publishes the world's effects at the frame
rate through the ``TopicHub``; ``inputs`` runs each client's text lines through its
``Session`` and takes joint commands and trajectories.
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
