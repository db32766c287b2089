"""The CRCL door: a TCP server whose connections are each a splitter, a session and a
``Controller``.

``CrclServer`` listens on ``127.0.0.1:64444`` by default (loopback, like the text
port). Each connection reads what arrives, cuts it into documents with its own
``DocumentSplitter`` and hands each to its ``Controller``, which runs it through the
connection's ``Session`` (source ``crcl HOST:PORT``) and writes the statuses back.
A connection never waits on a motion: GetStatus is answered while the arm moves.

Bad input never costs the server or another client (every case gets a ``CRCL_Error``
status whose ``StateDescription`` says what was wrong):

- a malformed or invalid document, text or markup between documents: that error, and
  the connection goes on with the next document (so does a document a bug in c2rviz
  fails on: ``INTERNAL_ERROR``, and the traceback in the log);
- a document that stalls half-sent for ``stall_timeout_s``: its bytes are dropped,
  that error, and the connection goes on;
- what the stream cannot be re-synchronised after (a document over
  ``max_document_bytes``, binary bytes, a ``<!DOCTYPE`` or other markup declaration):
  that error, then the documented close (the server ends its side, reads and drops
  what the client still sends for up to ``tcp_reading.LINGER_S``, then closes);
- one connection over ``max_connections``: an error status, then the close;
- statuses left unread past ``max_unread``: the connection is reset.

A long run of documents in one read is worked through ``tcp_reading.TURN_S`` at a time, so one
client's flood delays the others by no more than that; a document too large to parse
in that time (over ``PARSE_ON_LOOP_BYTES``) is parsed in the door's parsing process
(``parse_process``: it holds no lock of the server's; it starts with the first such
document), big documents of every client in the order they came, while the loop serves
the others; the loop takes the parsed commands in a slice at a time. A parsing process
that dies costs that document an error status; the next starts a new one.
"""

from __future__ import annotations

import asyncio
import logging
import time
from dataclasses import dataclass
from typing import Final

from ...protocol.limits import default, default_s
from ...session.services import Services
from ...session.session import Session
from ..parse_process import ParseProcess, ProcessLost
from ..tcp_reading import TURN_S, close_lingering
from .actions import ACTIONS
from .controller import Controller
from .documents import CommandInstance, parse_instance
from .errors import CrclError, CrclFramingError
from .framing import DocumentSplitter

log = logging.getLogger("c2rviz.crcl")

DEFAULT_PORT: Final = 64444
"""NIST's Java tools' port."""
READ_BYTES: Final = 65536
"""Most bytes read at once from a client."""
REFUSALS_SUMMED_S: Final = 60.0
"""Refused connections after the first are logged as one count per this interval [s]."""
SPLIT_BYTES: Final = 16384
"""Bytes of a read cut into documents at once [bytes]: the splitter scans every tag
(about 0.5 ms for this many), so a read of ``READ_BYTES`` goes in slices, the other
clients served between them."""
PARSE_ON_LOOP_BYTES: Final = 16384
"""The largest document parsed on the event loop [bytes]: a larger one (a parse runs at
about 3 MB/s, so past a turn's ``TURN_S``) is parsed in the door's parsing process
while the other clients go on, and this client's next documents wait for it."""
INTERNAL_ERROR: Final = "internal error reading the document (see the server log)"
"""The description of a document a bug in c2rviz could not run (the connection goes on)."""


@dataclass(frozen=True)
class CrclLimits:
    """What one CRCL client may cost (docs/limits.md; the ``crcl`` rows of
    ``session.limits.LIMITS``).

    Attributes:
        max_document_bytes: The largest document [bytes]; larger closes the connection.
        stall_timeout_s: How long half a document may wait for the rest [s].
        max_connections: CRCL clients at once per port; one more is told so and closed.
        max_unread: Statuses a client has not read [bytes]; more resets the connection.
    """

    max_document_bytes: int = default("crcl", "max_document_bytes")
    stall_timeout_s: float = default_s("crcl", "stall_timeout_s")
    max_connections: int = default("crcl", "max_connections")
    max_unread: int = default("crcl", "max_unread")


class CrclServer:
    """Listens for CRCL clients; each drives ``robot`` through a session of its own.

    Args:
        services: What sessions share (the world).
        robot: The robot its clients drive (None: the world's default).
        limits: What one client may cost.
    """

    def __init__(
        self, services: Services, robot: str | None = None, limits: CrclLimits | None = None
    ) -> None:
        self.services = services
        self.robot = robot
        self.limits = limits or CrclLimits()
        self._server: asyncio.Server | None = None
        self._tasks: set[asyncio.Task[None]] = set()
        self._open: set[_Connection] = set()
        self._served: set[_Connection] = set()
        self._door = f"crcl {id(self)}"
        self._refusals = _RefusalLog()
        self._parsing: ParseProcess | None = None
        self.refused = 0
        """Connections turned away (over ``max_connections``, or while stopping)."""
        self.address: tuple[str, int] | None = None
        """Where it listens, once started."""

    @property
    def connections(self) -> int:
        """Clients served now."""
        return len(self._served)

    async def start(self, host: str = "127.0.0.1", port: int = DEFAULT_PORT) -> tuple[str, int]:
        """Listen on ``host:port`` (0: a free port); return the address bound.

        Raises:
            OSError: the address cannot be listened on.
        """
        self._parsing = ParseProcess("CRCL parsing")  # (its process: on the first large document)
        self._server = await asyncio.start_server(self._accept, host, port)
        bound = self._server.sockets[0].getsockname()
        self.address = (str(bound[0]), int(bound[1]))
        self.services.world.faults.listeners.append(self._fault)
        return self.address

    def _fault(self, robot: str, text: str) -> None:
        """``fault disconnect`` on this door's robot: its clients are cut off now."""
        world = self.services.world
        if text == "fault disconnect" and robot == (self.robot or world.default):
            for connection in list(self._served):
                connection.shutdown()

    async def stop(self) -> None:
        """Stop listening and close every connection (commands under way are dropped)."""
        if self._server is None:
            return
        listeners = self.services.world.faults.listeners
        if self._fault in listeners:
            listeners.remove(self._fault)
        self._server.close()
        for connection in list(self._open):
            connection.shutdown()
        if self._tasks:
            await asyncio.wait(list(self._tasks), timeout=5.0)
        await self._server.wait_closed()
        self._server = None
        self._refusals.flush(final=True)
        if self._parsing is not None:
            await self._parsing.close()
            self._parsing = None

    async def _accept(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        task = asyncio.current_task()
        assert task is not None
        self._tasks.add(task)
        try:
            await self._serve(reader, writer)
        finally:
            self._tasks.discard(task)

    async def _serve(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        peer = writer.get_extra_info("peername")
        where = f"{peer[0]}:{peer[1]}" if isinstance(peer, tuple) else str(peer)
        session = Session(self.services, f"crcl {where}", self.robot)
        connection = _Connection(self, reader, writer, session, self._parsing)
        self._open.add(connection)
        try:
            await self._connection(connection, where)
        finally:
            self._open.discard(connection)

    async def _connection(self, connection: _Connection, where: str) -> None:
        if self._server is None or len(self._served) >= self.limits.max_connections:
            self.refused += 1
            self._refusals.refused(where, len(self._served), self.limits.max_connections)
            limit = self.limits.max_connections
            connection.controller.refuse_document(
                CrclError(f"too many CRCL connections (limit {limit}); closing")
            )
            await connection.close()
            return
        self._served.add(connection)
        self.services.count_clients(self._door, len(self._served))
        log.info("CRCL client %s connected", where)
        try:
            await connection.run()
        finally:
            self._served.discard(connection)
            self.services.count_clients(self._door, len(self._served))
            log.info("CRCL client %s left", where)


def _parse(doc: bytes) -> CommandInstance | CrclError:
    """``parse_instance`` in the parsing process: the document, or why it is refused."""
    try:
        return parse_instance(doc)
    except CrclError as error:
        return error


class _RefusalLog:
    """Logs the first connection refused, then how many more each ``REFUSALS_SUMMED_S``
    (a storm of clients over the cap costs a line a minute, not a line each)."""

    def __init__(self) -> None:
        self._more = 0
        self._timer: asyncio.TimerHandle | None = None

    def refused(self, where: str, served: int, limit: int) -> None:
        if self._timer is None:
            log.warning(
                "refused CRCL client %s: %d served already (limit %d); further refusals "
                "are counted every %g s",
                where, served, limit, REFUSALS_SUMMED_S,
            )  # fmt: skip
            self._timer = asyncio.get_running_loop().call_later(REFUSALS_SUMMED_S, self.flush)
        else:
            self._more += 1

    def flush(self, final: bool = False) -> None:
        """Log the refusals counted since the last line; go on counting unless there were
        none or this is the ``final`` line (the server stops)."""
        if self._timer is not None:
            self._timer.cancel()
            self._timer = None
        if self._more:
            log.warning(
                "refused %d more CRCL clients (too many connections) in the last %g s at most",
                self._more, REFUSALS_SUMMED_S,
            )  # fmt: skip
            self._more = 0
            if not final:
                loop = asyncio.get_running_loop()
                self._timer = loop.call_later(REFUSALS_SUMMED_S, self.flush)


class _Connection:
    """One client: its bytes, its splitter, its controller."""

    def __init__(
        self,
        server: CrclServer,
        reader: asyncio.StreamReader,
        writer: asyncio.StreamWriter,
        session: Session,
        parsing: ParseProcess | None = None,
    ) -> None:
        self.limits = server.limits
        self.parsing = parsing
        self.reader, self.writer = reader, writer
        self.splitter = DocumentSplitter(self.limits.max_document_bytes)
        self.controller = Controller(session, self.send, ACTIONS)
        self.closing = False

    def send(self, document: bytes) -> None:
        """Write one status; a client that leaves too many unread is reset."""
        transport = self.writer.transport
        if self.closing or transport.is_closing():
            return
        self.writer.write(document)
        unread = transport.get_write_buffer_size()
        if unread > self.limits.max_unread:
            log.warning("resetting a CRCL client: %d bytes of statuses unread", unread)
            self.closing = True
            transport.abort()

    async def run(self) -> None:
        loop = asyncio.get_running_loop()
        splitter, limits = self.splitter, self.limits
        # The stall clock runs from a document's first byte, however many reads bring the
        # rest; the time we spend on our own work meanwhile is added (``owed``), since the
        # client's bytes may be waiting unread in the socket while we work.
        pending_since: float | None = None
        owed = 0.0
        try:
            while not self.closing:
                timeout = None
                started = splitter.started_at
                if splitter.pending_bytes and started is not None:
                    if started != pending_since:
                        pending_since, owed = started, 0.0
                    timeout = max(started + owed + limits.stall_timeout_s - loop.time(), 0.0)
                try:
                    data = await asyncio.wait_for(self.reader.read(READ_BYTES), timeout)
                except asyncio.TimeoutError:
                    dropped = splitter.discard_pending()
                    self.controller.refuse_document(
                        CrclFramingError(
                            f"half a document ({dropped} bytes) stalled for "
                            f"{limits.stall_timeout_s:g} s: dropped; skipping to the next "
                            "document",
                            recoverable=True,
                        )
                    )
                    continue
                except (ConnectionError, OSError):
                    break
                if not data:
                    break
                fed = loop.time()
                for start in range(0, len(data), SPLIT_BYTES):
                    if start:
                        await asyncio.sleep(0)  # the other clients' turn between slices
                    if self.closing or splitter.closed:
                        break
                    await self._take(splitter.feed(data[start : start + SPLIT_BYTES], fed))
                if splitter.started_at is not None:
                    if splitter.started_at != pending_since:
                        pending_since, owed = splitter.started_at, 0.0
                    owed += loop.time() - fed
                if splitter.closed:
                    await self.close()
        finally:
            self.controller.close()
            if not self.closing:
                self.closing = True
                self.writer.close()

    async def _take(self, items: list[bytes | CrclFramingError]) -> None:
        """Run the documents (and report the errors) of one read, a turn's work at a time;
        a document over ``PARSE_ON_LOOP_BYTES`` is parsed off the loop meanwhile."""
        started = time.perf_counter()
        for item in items:
            if self.closing:
                return
            if isinstance(item, CrclFramingError):
                self.controller.refuse_document(item)
                continue
            try:
                if len(item) > PARSE_ON_LOOP_BYTES and self.parsing is not None:
                    try:
                        parsed = await self.parsing.run(_parse, item)
                    except ProcessLost as lost:
                        parsed = CrclError(f"{lost}: the document was not read")
                    started = time.perf_counter()  # the others had the loop meanwhile
                    if self.closing:
                        return
                    if isinstance(parsed, CrclError):
                        self.controller.refuse_document(parsed)
                    else:
                        self.controller.receive(parsed)
                else:
                    self.controller.receive(item)
            except Exception:  # a bug costs this document, never the connection
                log.exception("internal error reading a CRCL document")
                self.controller.refuse_document(CrclError(INTERNAL_ERROR))
            if time.perf_counter() - started > TURN_S:
                await asyncio.sleep(0)  # the other clients' turn
                started = time.perf_counter()

    def shutdown(self) -> None:
        """The server stops: nothing more is read or sent; the connection closes now."""
        self.controller.close()
        self.closing = True
        self.writer.transport.abort()  # the reads end (EOF): run and close return

    async def close(self) -> None:
        """The documented close (``tcp_reading.close_lingering``): statuses out, our side
        ended, the client's rest read and dropped until it closes or the linger ends (a
        reset would lose the last status), then closed."""
        self.controller.close()
        self.closing = True
        transport = self.writer.transport
        assert isinstance(transport, asyncio.Transport)  # a TCP stream: it reads too
        linger = close_lingering(transport, eof=False)
        if linger is None:
            return
        try:
            while await self.reader.read(READ_BYTES):
                pass  # dropped; the linger's end aborts the transport, and the read ends
        except (ConnectionError, OSError):
            pass
        finally:
            linger.cancel()
            self.writer.close()
