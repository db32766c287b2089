"""``Client``: a controller's blocking connection to c2rviz, one typed method per verb.

::

    from c2rviz import Client

    with Client(port=31000) as robot:
        robot.motion("on")
        robot.joints([0.5, 0, 0, 0, 0, 0, 0])   # [rad]; returns when the arm arrives
        print(robot.where(), robot.pose())

Every verb of the command language (``protocol.registry.VERBS``) has a method here
(``speaks`` tags it; a test fails when a verb has none) taking typed arguments and
returning a typed result (``records``). Angles are radians, lengths metres, unless the
connection chose degrees (``degrees()`` or ``Client(degrees=True)``): then angles are
degrees, both ways. Arguments are checked before anything is sent (``calls``); an
``error:`` reply raises ``CommandError`` with the server's message; a server gone
mid-call raises ``ConnectionLost`` (a ``ConnectionError``) naming the command.
``send(line)`` sends any line as typed. The REPL and the player use this client too.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TypeVar

from . import calls, records
from .calls import Call, count_problem, read_call, speaks
from .connect import ServerUnavailable
from .errors import CommandError, ConnectionLost
from .fault_verbs import FaultVerbs
from .lines import LineClient
from .options import COMMANDS_DIR, add_connection_args, default_address, find_script, server_address
from .plan_verbs import PlanVerbs
from .records import (
    JointLimit,
    MotionLimit,
    MotionStatus,
    Pose,
    RobotNames,
    VersionInfo,
)
from .scene_verbs import SceneVerbs
from .stream import WatchStream

__all__ = [
    "COMMANDS_DIR",
    "Client",
    "ConnectionLost",
    "ServerUnavailable",
    "add_connection_args",
    "default_address",
    "find_script",
    "server_address",
]

T = TypeVar("T")


class Client(LineClient, SceneVerbs, PlanVerbs, FaultVerbs):
    """A blocking connection with a method per verb; see the module docstring.

    Args (all but host and port by keyword):
        host, port: The command server (default 127.0.0.1:31000).
        timeout: Longest wait for one reply [s]; None (the default): no limit, as a reply
            may follow a long move. Past it ``ReplyTimeout`` (a ``TimeoutError``).
        retry_s: How long to keep retrying a refused connection [s] (default 10).
        degrees: Speak degrees from the start.
        robot: Drive this robot of a cell.
        max_reply: Longest reply line [bytes] (default 1 MiB).
        notify: Called with a short message when retrying to connect begins.

    It connects when entering ``with`` or at the first call; after a lost connection the
    next call reconnects (restoring the units and the robot).
    """

    def __enter__(self) -> Client:
        self.open()
        return self

    def call(self, call: Call[T]) -> T:
        """Send ``call``'s line and read its reply (every earlier reply must be read).

        Raises:
            CommandError, ConnectionLost, ServerUnavailable, UnexpectedReply, ArgumentError.
        """
        if self.pending:
            raise RuntimeError(f"a call with {self.pending} replies unread")
        if call.joint_count is not None or call.highest_index is not None:
            names = self.joint_names()
            count_problem(call, self.robot_name or "the robot", names)
        self._post(call.line, call.track, call.data)
        return read_call(call, self.read_reply())

    def send(self, line: str) -> str:
        """Send one line as typed; return its ``ok`` reply (the whole line).

        Raises:
            CommandError: the reply is ``error: ...``.
            ValueError: the line is blank or only a comment (nothing would answer).
        """
        reply = self.ask(line)
        if reply.startswith("error"):
            raise CommandError(line.strip(), reply)
        return reply

    @speaks("watch")
    def watch(self, hz: float | None = None) -> WatchStream:
        """The ``watch`` stream, on a connection of its own (this one's robot and units):
        iterate it for ``State`` and ``Event`` records; ``close()`` it (or use ``with``).

        Args:
            hz: Most ``state`` lines a second [1/s] (None: the server's frame rate).
        """
        return WatchStream(
            self.host,
            self.port,
            hz,
            degrees=self.in_degrees,
            robot=self.chosen_robot,
            max_line=self.max_reply,
        )

    # The joints.

    @speaks("joints")
    def joints(self, values: Sequence[float]) -> None:
        """Set all chain joints [rad, or deg; m for a prismatic joint]: at once (``motion
        off``), or travelling (``on``: returns on arrival; ``follow``: at once)."""
        return self.call(calls.joints(values))

    @speaks("move")
    def move(self, indices: Sequence[int] | int, values: Sequence[float]) -> None:
        """Set the joints at ``indices`` to ``values`` [rad, or deg; m], the rest stay."""
        return self.call(calls.move(indices, values))

    @speaks("home")
    def home(self) -> None:
        """Every chain joint to 0 (or its nearest limit)."""
        return self.call(calls.HOME)

    @speaks("rand")
    def rand(self) -> None:
        """Every chain joint to a random value within its limits (free, with the guard)."""
        return self.call(calls.RAND)

    @speaks("degrees")
    def degrees(self) -> None:
        """Angles of this connection in degrees from now on, both ways."""
        return self.call(calls.DEGREES)

    @speaks("radians")
    def radians(self) -> None:
        """Angles of this connection in radians from now on (the default)."""
        return self.call(calls.RADIANS)

    # Questions.

    @speaks("where")
    def where(self) -> tuple[float, ...]:
        """The chain's joint values now [rad, or deg; m] (mid-move too)."""
        return self.call(calls.WHERE)

    @speaks("pose")
    def pose(self) -> Pose:
        """The tool pose in the base frame: x, y, z [m], roll, pitch, yaw [rad, or deg]."""
        return self.call(calls.POSE)

    @speaks("limits")
    def limits(self) -> list[JointLimit]:
        """Each chain joint's range [rad, or deg; m] and unit, in index order."""
        return self.call(calls.LIMITS)

    @speaks("limits")
    def motion_limits(self) -> list[MotionLimit]:
        """Each chain joint's velocity, acceleration and jerk limits [rad, or deg; m per s,
        s^2, s^3] (``limits all``)."""
        return self.call(calls.MOTION_LIMITS)

    @speaks("names")
    def names(self) -> RobotNames:
        """The robot this connection drives and its chain's joint names, in index order."""
        names = self.call(calls.NAMES)
        self.robot_name, self._names = names  # what a joint count is checked against
        return names

    @speaks("version")
    def version(self) -> VersionInfo:
        """The server's version and the robot file it loaded."""
        return self.call(calls.VERSION)

    @speaks("help")
    def help(self) -> list[str]:
        """Every verb's usage, as the server lists them."""
        return self.call(calls.HELP)

    # The connection.

    @speaks("sleep")
    def sleep(self, seconds: float) -> None:
        """Pause this connection for ``seconds`` [s of the server's clock] (others go on)."""
        return self.call(calls.sleep(seconds))

    @speaks("bye")
    def bye(self) -> None:
        """Close this connection politely (a later call reconnects)."""
        self.call(calls.BYE)
        self.close()

    @speaks("quit")
    def quit(self) -> None:
        """Stop the server (command server and viewer); this connection closes."""
        self.call(calls.QUIT)
        self.close()

    # The tool point.

    @speaks("tool")
    def tool(self, pose: Sequence[float] | None = None) -> Pose:
        """Set the tool point relative to the end-effector link (x, y, z [m], roll, pitch,
        yaw [rad, or deg]) for every connection; return it (without ``pose``: as it is)."""
        return self.call(calls.tool(pose))

    @speaks("ik")
    def ik(self, pose: Sequence[float]) -> tuple[float, ...]:
        """Joint values [rad, or deg; m] that put the tool point at ``pose`` (x, y, z [m],
        roll, pitch, yaw [rad, or deg]); nothing moves."""
        return self.call(calls.ik(pose))

    @speaks("moveto")
    def moveto(self, pose: Sequence[float] | None = None, *, marker: int | None = None) -> None:
        """Go to a tool pose (x, y, z [m], roll, pitch, yaw [rad, or deg]) through joint
        space, or to marker N's pose (1: the oldest)."""
        return self.call(calls.moveto(pose, marker))

    @speaks("movel")
    def movel(self, pose: Sequence[float]) -> None:
        """The tool point travels a straight line to ``pose`` (x, y, z [m], roll, pitch,
        yaw [rad, or deg]) at this connection's ``lspeed``."""
        return self.call(calls.movel(pose))

    @speaks("lspeed")
    def lspeed(self, m_s: float | None = None) -> float:
        """Set ``movel``'s tool speed [m/s] (0 < V <= 5); return it (without one: as it is)."""
        return float(self.call(calls.setting("lspeed", "m_s", m_s, records.read_number)))

    # Motion.

    @speaks("motion")
    def motion(self, mode: str | None = None) -> str:
        """Set how this connection's moves travel: ``off`` (at once), ``on`` (the call
        returns on arrival) or ``follow`` (travel, return at once); return the mode."""
        return self.call(calls.motion(mode))

    @speaks("speed")
    def speed(self, percent: float | None = None) -> float:
        """Set this connection's moves to ``percent`` [% of the joints' limits, 1..100];
        return it (without one: as it is)."""
        return float(self.call(calls.setting("speed", "percent", percent, records.read_number)))

    @speaks("stop")
    def stop(self) -> None:
        """Bring the arm to rest within its limits; returns when it is."""
        return self.call(calls.STOP)

    @speaks("wait")
    def wait(self) -> None:
        """Return when the arm is at rest."""
        return self.call(calls.WAIT)

    @speaks("target")
    def target(self) -> tuple[float, ...]:
        """The joint values the arm is moving to, or stands at [rad, or deg; m]."""
        return self.call(calls.TARGET)

    @speaks("status")
    def status(self) -> MotionStatus:
        """Whether the arm moves, and the seconds until it is at rest [s of the server's clock]."""
        return self.call(calls.STATUS)

    # Cells.

    @speaks("robot")
    def robot(self, name: str | None = None) -> str:
        """Drive robot ``name`` of the cell from now on; return the robot driven."""
        return self.call(calls.robot(name))

    @speaks("robots")
    def robots(self) -> dict[str, int | None]:
        """The cell's robots and their command ports."""
        return self.call(calls.ROBOTS)
