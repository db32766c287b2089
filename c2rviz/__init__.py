"""c2rviz: text command-and-control of a robot arm, shown live in a browser.

A ROS-free re-creation of NIST's "text based command and control of a ROS RViz
visualization": clients send one-line commands over TCP (port 31000) and the
arm moves in a viser page. The parts, each usable alone:

- ``commands``: the pure parser (line -> frozen command);
- ``robot``: the Pinocchio model and its serial chain;
- ``session`` / ``world``: one client's units and the shared state;
- ``server``: the asyncio TCP server;
- ``scene`` / ``viewer``: what is drawn, and the viser implementation;
- ``config`` / ``cli``: cmdinterpreter.ini, flags, ``main``.
"""

from .commands import parse_line
from .errors import C2rvizError
from .robot import Robot
from .scene import Marker, RecordingScene, Scene
from .server import CommandServer
from .session import Session
from .world import World

__all__ = [
    "C2rvizError",
    "CommandServer",
    "Marker",
    "RecordingScene",
    "Robot",
    "Scene",
    "Session",
    "World",
    "parse_line",
]
__version__ = "0.1.0"
