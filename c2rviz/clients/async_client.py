"""``AsyncClient``: ``Client`` for asyncio, the same methods as coroutines.

::

    import asyncio
    from c2rviz import AsyncClient

    async def main() -> None:
        async with AsyncClient(port=31000) as robot:
            await robot.motion("on")
            await robot.joints([0.5, 0, 0, 0, 0, 0, 0])   # [rad]; returns on arrival
            print(await robot.where())

    asyncio.run(main())

Every method takes the arguments of ``Client``'s of the same name, in the same units
(radians and metres, or degrees once the connection chose them), checks them before
anything is sent, and returns the same record (a test keeps the two signature for
signature). Calls on one client are taken in turn; open several clients to have
several commands waiting at once (each is a connection, a session of its own).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TypeVar

from ..errors import C2rvizError
from ..protocol.grammar import parse_line
from . import calls, records
from .aio_lines import AsyncLineClient, AsyncWatchStream
from .aio_scene_verbs import AsyncSceneVerbs
from .calls import Call, count_problem, read_call, speaks
from .errors import CommandError
from .fault_verbs import AsyncFaultVerbs
from .plan_verbs import AsyncPlanVerbs
from .records import (
    JointLimit,
    MotionLimit,
    MotionStatus,
    Pose,
    RobotNames,
    VersionInfo,
)

__all__ = ["AsyncClient"]

T = TypeVar("T")


class AsyncClient(AsyncLineClient, AsyncSceneVerbs, AsyncPlanVerbs, AsyncFaultVerbs):
    """An asyncio connection with a coroutine per verb; arguments as ``Client``'s.

    It connects when entering ``async with`` or at the first call; after a lost
    connection the next call reconnects (restoring the units and the robot).
    """

    async def __aenter__(self) -> AsyncClient:
        await self.open()
        return self

    async def call(self, call: Call[T]) -> T:
        """Send ``call``'s line and read its reply (see ``Client.call``)."""
        if call.joint_count is not None or call.highest_index is not None:
            names = await self.joint_names()
            count_problem(call, self.robot_name or "the robot", names)
        return read_call(call, await self.ask(call.line, call.track))

    async def send(self, line: str) -> str:
        """Send one line as typed; return its ``ok`` reply (``CommandError`` for an error).

        Raises:
            ValueError: the line is blank or only a comment (nothing would answer).
        """
        try:
            command = parse_line(line)
        except C2rvizError:
            command = False  # the server will answer with an error
        if command is None:
            raise ValueError(f"{line!r} is not a command: the server would not answer")
        text = line.strip()
        reply = await self.ask(text, command)
        if reply.startswith("error"):
            raise CommandError(text, reply)
        return reply

    @speaks("watch")
    def watch(self, hz: float | None = None) -> AsyncWatchStream:
        """The ``watch`` stream on a connection of its own (``async for`` its ``State`` and
        ``Event`` records; ``async with`` or ``close()``); ``hz``: most states a second."""
        return AsyncWatchStream(
            self.host,
            self.port,
            hz,
            degrees=self.in_degrees,
            robot=self.chosen_robot,
            max_line=self.max_reply,
        )

    @speaks("joints")
    async def joints(self, values: Sequence[float]) -> None:
        """Set all chain joints [rad, or deg; m for a prismatic joint]: at once (``motion
        off``), or travelling (``on``: returns on arrival; ``follow``: at once)."""
        return await self.call(calls.joints(values))

    @speaks("move")
    async def move(self, indices: Sequence[int] | int, values: Sequence[float]) -> None:
        """Set the joints at ``indices`` to ``values`` [rad, or deg; m], the rest stay."""
        return await self.call(calls.move(indices, values))

    @speaks("home")
    async def home(self) -> None:
        """Every chain joint to 0 (or its nearest limit)."""
        return await self.call(calls.HOME)

    @speaks("rand")
    async def rand(self) -> None:
        """Every chain joint to a random value within its limits (free, with the guard)."""
        return await self.call(calls.RAND)

    @speaks("degrees")
    async def degrees(self) -> None:
        """Angles of this connection in degrees from now on, both ways."""
        return await self.call(calls.DEGREES)

    @speaks("radians")
    async def radians(self) -> None:
        """Angles of this connection in radians from now on (the default)."""
        return await self.call(calls.RADIANS)

    @speaks("where")
    async def where(self) -> tuple[float, ...]:
        """The chain's joint values now [rad, or deg; m] (mid-move too)."""
        return await self.call(calls.WHERE)

    @speaks("pose")
    async def pose(self) -> Pose:
        """The tool pose in the base frame: x, y, z [m], roll, pitch, yaw [rad, or deg]."""
        return await self.call(calls.POSE)

    @speaks("limits")
    async def limits(self) -> list[JointLimit]:
        """Each chain joint's range [rad, or deg; m] and unit, in index order."""
        return await self.call(calls.LIMITS)

    @speaks("limits")
    async def motion_limits(self) -> list[MotionLimit]:
        """Each chain joint's velocity, acceleration and jerk limits [rad, or deg; m per s,
        s^2, s^3] (``limits all``)."""
        return await self.call(calls.MOTION_LIMITS)

    @speaks("names")
    async def names(self) -> RobotNames:
        """The robot this connection drives and its chain's joint names, in index order."""
        names = await self.call(calls.NAMES)
        self.robot_name, self._names = names  # what a joint count is checked against
        return names

    @speaks("version")
    async def version(self) -> VersionInfo:
        """The server's version and the robot file it loaded."""
        return await self.call(calls.VERSION)

    @speaks("help")
    async def help(self) -> list[str]:
        """Every verb's usage, as the server lists them."""
        return await self.call(calls.HELP)

    @speaks("sleep")
    async def sleep(self, seconds: float) -> None:
        """Pause this connection for ``seconds`` [s of the server's clock] (others go on)."""
        return await self.call(calls.sleep(seconds))

    @speaks("bye")
    async def bye(self) -> None:
        """Close this connection politely (a later call reconnects)."""
        await self.call(calls.BYE)
        await self.close()

    @speaks("quit")
    async def quit(self) -> None:
        """Stop the server (command server and viewer); this connection closes."""
        await self.call(calls.QUIT)
        await self.close()

    @speaks("tool")
    async def tool(self, pose: Sequence[float] | None = None) -> Pose:
        """Set the tool point relative to the end-effector link (x, y, z [m], roll, pitch,
        yaw [rad, or deg]) for every connection; return it (without ``pose``: as it is)."""
        return await self.call(calls.tool(pose))

    @speaks("ik")
    async def ik(self, pose: Sequence[float]) -> tuple[float, ...]:
        """Joint values [rad, or deg; m] that put the tool point at ``pose`` (x, y, z [m],
        roll, pitch, yaw [rad, or deg]); nothing moves."""
        return await self.call(calls.ik(pose))

    @speaks("moveto")
    async def moveto(
        self, pose: Sequence[float] | None = None, *, marker: int | None = None
    ) -> None:
        """Go to a tool pose (x, y, z [m], roll, pitch, yaw [rad, or deg]) through joint
        space, or to marker N's pose (1: the oldest)."""
        return await self.call(calls.moveto(pose, marker))

    @speaks("movel")
    async def movel(self, pose: Sequence[float]) -> None:
        """The tool point travels a straight line to ``pose`` (x, y, z [m], roll, pitch,
        yaw [rad, or deg]) at this connection's ``lspeed``."""
        return await self.call(calls.movel(pose))

    @speaks("lspeed")
    async def lspeed(self, m_s: float | None = None) -> float:
        """Set ``movel``'s tool speed [m/s] (0 < V <= 5); return it (without one: as it is)."""
        return float(await self.call(calls.setting("lspeed", "m_s", m_s, records.read_number)))

    @speaks("motion")
    async def motion(self, mode: str | None = None) -> str:
        """Set how this connection's moves travel: ``off`` (at once), ``on`` (the call
        returns on arrival) or ``follow`` (travel, return at once); return the mode."""
        return await self.call(calls.motion(mode))

    @speaks("speed")
    async def speed(self, percent: float | None = None) -> float:
        """Set this connection's moves to ``percent`` [% of the joints' limits, 1..100];
        return it (without one: as it is)."""
        return float(
            await self.call(calls.setting("speed", "percent", percent, records.read_number))
        )

    @speaks("stop")
    async def stop(self) -> None:
        """Bring the arm to rest within its limits; returns when it is."""
        return await self.call(calls.STOP)

    @speaks("wait")
    async def wait(self) -> None:
        """Return when the arm is at rest."""
        return await self.call(calls.WAIT)

    @speaks("target")
    async def target(self) -> tuple[float, ...]:
        """The joint values the arm is moving to, or stands at [rad, or deg; m]."""
        return await self.call(calls.TARGET)

    @speaks("status")
    async def status(self) -> MotionStatus:
        """Whether the arm moves, and the seconds until it is at rest [s of the server's clock]."""
        return await self.call(calls.STATUS)

    @speaks("robot")
    async def robot(self, name: str | None = None) -> str:
        """Drive robot ``name`` of the cell from now on; return the robot driven."""
        return await self.call(calls.robot(name))

    @speaks("robots")
    async def robots(self) -> dict[str, int | None]:
        """The cell's robots and their command ports."""
        return await self.call(calls.ROBOTS)
