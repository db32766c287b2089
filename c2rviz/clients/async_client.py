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
anything is sent, and returns the same record: the verbs are written once, here
(``aio_verbs``, ``aio_scene_verbs``), and ``Client``'s are generated from them.
Calls on one client are taken in turn; open several clients to have several commands
waiting at once (each is a connection, a session of its own).
"""

from __future__ import annotations

from typing import TypeVar

from ..errors import C2rvizError
from ..protocol.grammar import parse_line
from ..protocol.replies import SHUTTING_DOWN
from .aio_lines import AsyncLineClient, AsyncWatchStream
from .aio_scene_verbs import AsyncSceneVerbs
from .aio_verbs import AsyncVerbs
from .calls import Call, count_problem, read_call, speaks
from .errors import CommandError, ServerShutdown

__all__ = ["AsyncClient"]

T = TypeVar("T")


class AsyncClient(AsyncLineClient, AsyncVerbs, AsyncSceneVerbs):
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
        reply = await self.ask(call.line, call.track)
        if reply == SHUTTING_DOWN:  # the server goes away mid-call: ConnectionLost's case
            await self.close()
            raise ServerShutdown(self.host, self.port, call.line, reply)
        return read_call(call, reply)

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
        if reply == SHUTTING_DOWN:
            await self.close()
            raise ServerShutdown(self.host, self.port, text, reply)
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
