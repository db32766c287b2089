"""c2rviz: text command-and-control of a robot arm, shown live in a browser.

A ROS-free re-creation of NIST's "text based command and control of a ROS RViz
visualization": clients send one-line commands over TCP (port 31000) and the
arm moves in a viser page. A controller talks to it with ``Client`` (blocking) or
``AsyncClient`` (asyncio): a method per verb, typed or ``robot.VERB(*words)``
(docs/testing.md). The parts, each usable alone:

- ``protocol``: the pure parser (line -> frozen command), the verbs and the replies;
- ``robot``: the Pinocchio model and its serial chain, and where its URDF and meshes
  come from;
- ``session`` / ``world``: one client's units and the shared state;
- ``transports``: the doors (the text TCP port, CRCL, rosbridge);
- ``view``: what is drawn, with viser;
- ``app``: cmdinterpreter.ini, flags, ``main``;
- ``clients``: ``Client``, ``AsyncClient``, the REPL and the player.

docs/architecture.md has every package and module.

Importing the package is cheap (the clients use the parser alone); the heavy
parts (Pinocchio, viser) load when first named.
"""

from importlib import import_module
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # what type checkers see of the lazy names below
    from .clients.client import AsyncClient, Client
    from .clients.connection import ServerUnavailable
    from .clients.errors import CommandError, ConnectionLost
    from .clients.records import Event, JointLimit, Pose, State
    from .clients.task_calls import PlanSummary

__all__ = [
    "__version__",
    "AsyncClient",
    "C2rvizError",
    "Client",
    "CommandError",
    "ConnectionLost",
    "CommandServer",
    "Event",
    "JointLimit",
    "Marker",
    "PlanSummary",
    "Pose",
    "RecordingScene",
    "Robot",
    "Scene",
    "ServerUnavailable",
    "Session",
    "State",
    "World",
    "parse_line",
]
__version__ = "0.2.0"
"""The version of c2rviz (the ``version`` verb and the package report it)."""

_HOME = {
    "C2rvizError": "errors",
    "CommandServer": "transports.tcp_server",
    "Marker": "world.observer",
    "RecordingScene": "world.observer",
    "Robot": "robot.model",
    "Scene": "world.observer",
    "Session": "session.session",
    "World": "world.world",
    "parse_line": "protocol.grammar",
}


_HOME.update(  # a controller's side: the clients (no Pinocchio, no viser)
    {
        "AsyncClient": "clients.client",
        "Client": "clients.client",
        "CommandError": "clients.errors",
        "ConnectionLost": "clients.errors",
        "Event": "clients.records",
        "JointLimit": "clients.records",
        "Pose": "clients.records",
        "PlanSummary": "clients.task_calls",
        "ServerUnavailable": "clients.connection",
        "State": "clients.records",
    }
)


def __getattr__(name: str) -> Any:
    if name in _HOME:
        return getattr(import_module(f".{_HOME[name]}", __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
