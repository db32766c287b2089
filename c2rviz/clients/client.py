"""``Client``: a controller's blocking connection to c2rviz, a method per verb.

::

    from c2rviz import Client

    with Client(port=31000) as robot:
        robot.motion("on")
        robot.joints([0.5, 0, 0, 0, 0, 0, 0])   # [rad]; returns when the arm arrives
        print(robot.where(), robot.pose())

Every verb of the command language (``protocol.registry.VERBS``) is a method here.
The typed ones (``speaks`` tags each with its verb) take typed arguments and return a
typed result (``records``); they are written once, for ``AsyncClient`` (below;
``aio_verbs``, ``aio_scene_verbs``), and ``scripts/unasync_clients.py`` writes their
blocking twins (``verbs``, ``scene_verbs``). A verb of the registry with no typed
method is a method all the same: ``robot.VERB(*words)`` sends the line and returns its
``ok`` reply, as ``send`` does (a new verb needs no client code: docs/architecture.md).
Angles are radians, lengths metres, unless the connection chose degrees (``degrees()``
or ``Client(degrees=True)``): then angles are degrees, both ways. Arguments are checked
before anything is sent (``calls``); an ``error:`` reply raises ``CommandError`` with
the server's message; a server gone mid-call raises ``ConnectionLost`` (a
``ConnectionError``) naming the command, also when it said it is shutting down
(``ServerShutdown``, a ``CommandError`` too).
``send(line)`` sends any line as typed. The REPL and the player use this client too.

``AsyncClient``: ``Client`` for asyncio, the same methods as coroutines.

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
from .lines import LineClient
from .scene_verbs import SceneVerbs
from .stream import WatchStream
from .verbs import Verbs

T = TypeVar("T")


class Client(LineClient, Verbs, SceneVerbs):
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
            CommandError, ConnectionLost (``ServerShutdown``: the server stopped while the
            call waited), ServerUnavailable, UnexpectedReply, ArgumentError.
        """
        if self.pending:
            raise RuntimeError(f"a call with {self.pending} replies unread")
        if call.joint_count is not None or call.highest_index is not None:
            names = self.joint_names()
            count_problem(call, self.robot_name or "the robot", names)
        self._post(call.line, call.track, call.data)
        reply = self.read_reply()
        if reply == SHUTTING_DOWN:  # the server goes away mid-call: ConnectionLost's case
            self.close()
            raise ServerShutdown(self.host, self.port, call.line, reply)
        return read_call(call, reply)

    def send(self, line: str) -> str:
        """Send one line as typed; return its ``ok`` reply (the whole line).

        Raises:
            CommandError: the reply is ``error: ...``.
            ValueError: the line is blank or only a comment (nothing would answer).
        """
        reply = self.ask(line)
        if reply == SHUTTING_DOWN:
            self.close()
            raise ServerShutdown(self.host, self.port, line.strip(), reply)
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
