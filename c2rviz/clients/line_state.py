"""What a connection to the command server remembers, for both line clients.

``LineClient`` (a blocking socket) and ``AsyncLineClient`` (asyncio streams) differ in
how they read and write; what they remember is the same, and is kept here once: the
server's address and limits, the unit mode and the robot the connection chose (which
a reconnect restores), and the robot's joint names (asked once per connection and
robot). No I/O.
"""

from __future__ import annotations

from ..protocol.verbs.arm import RobotChoice
from ..protocol.verbs.seed import Units
from .errors import CommandError, UnexpectedReply

__all__ = ["MAX_REPLY_BYTES", "LineState"]

MAX_REPLY_BYTES = 1 << 20
"""Longest reply line a client reads [bytes]; past it the connection is closed."""


class LineState:
    """A connection's memory (see the module docstring).

    Attributes:
        host, port: The command server.
        timeout: Longest wait for one reply [s] (None: as long as it takes: a reply may
            follow a long move or ``sleep``).
        retry_s: How long to keep retrying a refused connection [s].
        max_reply: Longest reply line [bytes].
        chosen_robot: The robot a ``robot NAME`` line chose (the server said ``ok``);
            None: the port's own robot.
        robot_name, names: From ``names``, once ``joint_names()`` has asked.
    """

    def __init__(
        self,
        host: str = "127.0.0.1",
        port: int = 31000,
        *,
        timeout: float | None = None,
        retry_s: float = 10.0,
        degrees: bool = False,
        robot: str | None = None,
        max_reply: int = MAX_REPLY_BYTES,
    ) -> None:
        """Args:
        host, port: The command server.
        timeout: Longest wait for one reply [s]; None: no limit.
        retry_s: How long to keep retrying a refused connection [s].
        degrees: Speak degrees (the connection sends ``degrees`` when it opens).
        robot: Drive this robot of a cell (``robot NAME`` when it opens).
        max_reply: Longest reply line [bytes].
        """
        self.host = host
        self.port = port
        self.timeout = timeout
        self.retry_s = retry_s
        self.max_reply = max_reply
        self._degrees = degrees
        self.chosen_robot = robot
        self._insist = robot is not None  # the first open refuses a robot the server lacks
        self.robot_name: str | None = None
        self._names: tuple[str, ...] | None = None

    @property
    def in_degrees(self) -> bool:
        """The connection's angle unit is degrees (as last confirmed by the server)."""
        return self._degrees

    def _remember(self, reply: str, tracked: object) -> None:
        """After ``reply`` to a ``Units`` or ``RobotChoice`` command: what it chose."""
        if reply.startswith("ok"):
            if isinstance(tracked, Units):
                self._degrees = tracked.degrees
            elif isinstance(tracked, RobotChoice) and tracked.name is not None:
                self.chosen_robot = tracked.name
                self._names = None  # another robot: other joints

    def _robot_refused(self, line: str, reply: str) -> CommandError | None:
        """After restoring the chosen robot (``line``) on a new connection: the error to
        raise (the connection closed) when the robot chosen at construction is not the
        server's; a robot chosen later and gone from a restarted server is forgotten."""
        if reply.startswith("ok"):
            return None
        self.chosen_robot = None
        return CommandError(line, reply) if self._insist else None

    def _take_names(self, reply: str) -> tuple[str, ...]:
        """The joint names from the reply to ``names`` (remembered, with the robot's).

        Raises:
            CommandError: the server refused ``names``.
            UnexpectedReply: the reply is not a c2rviz one.
        """
        if reply.startswith("error"):
            raise CommandError("names", reply)
        robot, _, names = reply[3:].partition(" ")
        if not reply.startswith("ok ") or not robot or not names or " " in names:
            raise UnexpectedReply("names", reply)
        self.robot_name = robot
        self._names = tuple(names.split(","))
        return self._names
