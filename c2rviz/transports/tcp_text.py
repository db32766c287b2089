"""The seed's door: the text protocol over TCP, an asyncio driver of the line framer.

Each connection is an ``asyncio.Protocol``: its ``protocol.framing.LineFramer``
cuts what arrives into lines, every complete line runs through the connection's
``Session`` (the one way in), and all lines of one batch (up to the framer's
``BATCH_BYTES`` of them: a big read is run in batches, one loop turn each) are
answered with one write. A turn also ends after
``TURN_S`` of work, so a flood of costly lines (a ``mark`` computes forward
kinematics) delays the other clients no more than a flood of cheap ones.
Nothing here knows kinematics or drawing. The limits in ``config.ServerLimits``
bound what one client can cost; a client that breaks one is told why and
closed, and no other client notices.
"""

from __future__ import annotations

import asyncio
import logging
import time
from collections.abc import Awaitable, Sequence
from itertools import chain, islice
from typing import Protocol

from ..errors import C2rvizError, LineTooLong
from ..observers.watch import STREAM_ALLOWANCE_BYTES
from ..planning.errors import WENT_AWAY
from ..protocol import replies
from ..protocol.framing import Line, LineFramer
from ..protocol.grammar import ForeignProtocol
from ..session.services import ServerLimits, Services
from ..session.session import BATCHED, Session
from .tcp_reading import (
    TURN_S,
    StopScan,
    close_lingering,
    is_command,
    is_stop,
    pace_reading,
    stop_plans,
    waited_reply,
)

log = logging.getLogger("c2rviz.server")


class Host(Protocol):
    """What a connection needs of the server that accepted it (``tcp_server.CommandServer``)."""

    services: Services
    limits: ServerLimits
    robot: str | None
    viewer_url: str | None

    def admit(self, connection: Connection) -> str | None: ...

    def release(self, connection: Connection) -> None: ...

    def request_quit(self) -> None: ...


class Connection(asyncio.Protocol):
    """One TCP client: its buffer, its session and its timers.

    Lines run in order. A reply that waits (an awaitable from the handler, such as
    ``sleep``'s) holds the lines read behind it in ``backlog`` (and the framer) until it
    comes, while other connections go on. Reading goes on behind it (``tcp_reading``): a
    ``stop`` read there cancels the connection's plans at once, and the end of the stream
    cancels them all (its client went away: the plan lane is free for the others).
    """

    def __init__(self, server: Host) -> None:
        self.server = server
        self.limits = server.limits
        self.session = Session(server.services, robot=server.robot)
        self.transport: asyncio.Transport | None = None
        self.peer = "?"
        self.framer = LineFramer(self.limits.max_line)
        self.backlog: Sequence[Line] = []  # lines read but waiting behind a reply
        self.pending: asyncio.Future[str] | None = None  # the reply being waited for
        self.yield_timer: asyncio.Handle | None = None  # set while yielding to other clients
        self.partial_timer: asyncio.TimerHandle | None = None
        self.linger_timer: asyncio.TimerHandle | None = None
        self.closing = False
        self.eof = False
        self.halted = False  # a stop or the end was seen ahead: this client's plans stop
        self.scan = StopScan()  # how far the framer's buffer was looked at for a `stop`
        self.closed = asyncio.get_running_loop().create_future()
        self.stream = server.services.watch.open(self.session, self)  # idle until `watch`
        clock = server.services.world.clock
        self.virtual = clock.virtual
        self.hold = clock.hold()  # a virtual clock waits while this client is busy

    @property
    def waiting(self) -> bool:
        """Reading is paused: behind a reply, or yielding to the other clients."""
        return self.pending is not None or self.yield_timer is not None

    # asyncio callbacks

    def connection_made(self, transport: asyncio.BaseTransport) -> None:
        assert isinstance(transport, asyncio.Transport)
        self.transport = transport
        peer = transport.get_extra_info("peername")
        self.peer = f"{peer[0]}:{peer[1]}" if isinstance(peer, tuple) else str(peer)
        self.session.set_source(f"tcp {self.peer}")
        refusal = self.server.admit(self)
        if refusal is not None:
            self.hold.close()
            self._close_with(refusal)

    def connection_lost(self, exc: Exception | None) -> None:
        self._cancel_timers()
        self.closing = True
        self.hold.close()
        self.server.services.watch.close(self.session)
        if self.pending is not None:
            self.pending.cancel()
        self.server.services.worker.go_on(self.session)
        self.server.release(self)
        if not self.closed.done():
            self.closed.set_result(None)

    def data_received(self, data: bytes) -> None:
        if self.closing:
            return
        if self.pending is not None:  # read ahead behind a reply (the class's docstring)
            self.framer.feed(data)
            self._look_ahead()
            return
        self.hold.take()  # it speaks: busy (it may have only listened since `watch`)
        self.framer.feed(data)
        if not self.waiting:  # else reading is paused; the wake-up goes on from here
            self._consume()

    def eof_received(self) -> bool:
        self.eof = True
        if self.closing:
            return False  # done lingering: asyncio closes the transport
        if self.pending is not None:  # it went away (or sends no more): its plans stop
            self.halted = True
            self.server.services.worker.halt(self.session, WENT_AWAY)
        if not self.waiting:
            self._finish()
        return True  # keep the write side open until the replies are out

    # The watch stream (c2rviz.watch) writes only while the write buffer is low.

    def pause_writing(self) -> None:
        self.stream.pause()

    def resume_writing(self) -> None:
        self.stream.resume()

    # line handling

    def _consume(self) -> None:
        """Run one batch of the complete lines the framer holds; keep the rest."""
        framer = self.framer
        lines = framer.take()
        if lines is not None:
            if self.partial_timer is not None:  # the line it timed is finished
                self.partial_timer.cancel()
                self.partial_timer = None
            self._run(lines)
        if self.closing or self.waiting:
            return  # while paused we do not read, so an unfinished line is not the client's fault
        if framer.has_line:  # more complete lines: let the other clients in first
            self._yield([])
        elif framer.too_long:
            self._close_with(replies.error(LineTooLong(self.limits.max_line)))
        elif framer.buffer and self.partial_timer is None:
            self.partial_timer = asyncio.get_running_loop().call_later(
                self.limits.partial_timeout_s, self._partial_timeout
            )

    def _run(self, lines: Sequence[Line]) -> None:
        """Answer ``lines`` (``_run_lines``); with a virtual clock, as this client's hold
        (``Clock.hold``): its replies that wait on the clock release it while they wait, and
        a client whose last line was ``watch`` only listens (released until it speaks)."""
        hold = self.hold
        if not self.virtual:  # real or scaled time: holds are no-ops, skip them
            self._run_lines(lines)
            return
        with hold.acting():
            self._run_lines(lines)
        if self.session.listens and not (self.waiting or self.closing):
            hold.release()

    def _run_lines(self, lines: Sequence[Line]) -> None:
        """Answer ``lines`` in order, stopping at a reply that waits, bye, quit or a fatal line,
        or after ``TURN_S`` of work (the rest runs after the other clients' turns)."""
        out: list[str] = []
        reply = out.append
        session = self.session
        run = session.run
        batch = session.set_joints_batch
        count = len(lines)
        started = time.perf_counter()
        numbered = enumerate(lines)
        for i, line in numbered:
            if i % _TURN_CHECK == _TURN_CHECK - 1 and time.perf_counter() - started > TURN_S:
                self._write(out)
                self._yield(lines[i:])
                return
            try:
                if not isinstance(line, str):
                    raise line
                if self.halted and not self.eof and is_stop(line):
                    self.halted = False  # its turn: the plans sent after it run
                    session.services.worker.go_on(session)
                if line.startswith(BATCHED) and i + 1 < count:  # a run needs two lines
                    taken = batch(lines, i)
                    if taken:  # the lines after it were answered with it: skip them
                        next(islice(numbered, taken - 1, taken - 1), None)
                        out.extend([replies.OK] * taken)
                        continue
                answer = run(line)
                if answer is None:
                    continue
                if not isinstance(answer, str):  # a reply that waits
                    self._write(out)
                    self._wait(answer, lines[i + 1 :])
                    return
                reply(answer)
                if session.hangup is not None:
                    self._write(out)
                    self._hang_up(lines[i + 1 :])
                    return
            except ForeignProtocol:  # a browser, most likely: an HTTP answer it can show
                self._write(out)
                if not self.closing and self.transport is not None:
                    self.transport.write(replies.not_http(self.server.viewer_url))
                self._close()  # the rest of the request (its headers, a body) never runs
                return
            except LineTooLong as exc:
                out.append(replies.error(exc))
                self._write(out)
                self._close()
                return
            except C2rvizError as exc:
                reply(replies.error(exc))
            except Exception:  # a bug must cost one reply, never the server
                log.exception("internal error on %r from %s", line, self.peer)
                reply(replies.error("internal error (see the server log)"))
        self._write(out)

    def _hang_up(self, rest: Sequence[Line]) -> None:
        """After ``bye`` or ``quit``: close (``quit`` also stops the program)."""
        if self.session.hangup == "quit":
            self._write([replies.SHUTTING_DOWN] * self._unanswered(rest))
            self.server.request_quit()  # before the close: a client seeing EOF sees it done
        self._close()

    def _wait(self, answer: Awaitable[str], rest: Sequence[Line]) -> None:
        """Stop reading until ``answer`` is ready; then reply and run ``rest``."""
        self.backlog = rest
        pending = asyncio.ensure_future(answer)
        self.pending = pending
        pending.add_done_callback(self._answered)
        self.scan.reset()
        if not self.halted and any(map(is_stop, rest)):
            self._stop_ahead()
        self._look_ahead()

    def _look_ahead(self) -> None:
        """Behind a reply that waits: act on a ``stop`` read ahead, and stop reading once
        ``tcp_reading.LOOK_AHEAD_BYTES`` wait (the lines run in their turn)."""
        if not self.halted and self.scan.stop_in(self.framer):
            self._stop_ahead()
        if self.transport is not None and not self.closing:
            pace_reading(self.transport, len(self.framer.buffer), self.eof)

    def _stop_ahead(self) -> None:
        self.halted = True
        stop_plans(self.session)

    def _answered(self, pending: asyncio.Future[str]) -> None:
        if pending is not self.pending:
            return
        self.pending = None
        if not self.closing:
            self._write([waited_reply(pending, self.peer)])
            self._go_on()

    def _yield(self, rest: Sequence[Line]) -> None:
        """Stop reading for a loop turn, so the other clients go first; then run ``rest``."""
        self.backlog = rest
        self._pause_reading()
        self.yield_timer = asyncio.get_running_loop().call_soon(self._yielded)

    def _yielded(self) -> None:
        self.yield_timer = None
        if not self.closing:
            self._go_on()

    def _go_on(self) -> None:
        """Run the lines that waited, then what is buffered; resume reading when done."""
        backlog, self.backlog = self.backlog, []
        self.scan.reset()
        self._run(backlog)
        if self.closing or self.waiting:
            return
        self._consume()
        if self.closing or self.waiting:
            return
        if self.eof:
            self._finish()
        elif self.transport is not None:
            self.transport.resume_reading()

    def _finish(self) -> None:
        """The client has sent all it will: a last line without its newline is a line too
        (as ``nc -q1`` users expect); answer it, then close."""
        if self.partial_timer is not None:
            self.partial_timer.cancel()
            self.partial_timer = None
        last = self.framer.rest()
        if last:
            self._run(last)
        if not (self.closing or self.waiting):
            self._close()

    def _pause_reading(self) -> None:
        assert self.transport is not None
        self.transport.pause_reading()

    def _partial_timeout(self) -> None:
        self.partial_timer = None
        if self.framer.buffer and not self.closing:
            self._close_with(replies.incomplete_line(self.limits.partial_timeout_s))

    # output and closing

    def _write(self, out: list[str]) -> None:
        if not out or self.closing or self.transport is None or self.transport.is_closing():
            return
        self.transport.write(("\n".join(out) + "\n").encode())
        unread = self.transport.get_write_buffer_size()
        if unread > self.limits.max_unread + (STREAM_ALLOWANCE_BYTES if self.stream.used else 0):
            log.warning("closing %s: %d bytes of replies unread", self.peer, unread)
            self.closing = True
            self.transport.abort()

    def drop(self) -> None:
        """A fault cuts this client off (``fault disconnect``): close now, answering nothing
        more."""
        if not self.closing:
            self._close()
            if self.pending is not None:
                self.pending.cancel()

    def _close_with(self, text: str) -> None:
        self._write([text])
        self._close()

    def _close(self) -> None:
        """Send what is queued, then close without a reset (``tcp_reading.close_lingering``:
        what the client still sends is dropped, as ``closing`` is set)."""
        self.closing = True
        self.framer.clear()
        self._cancel_timers()
        if self.transport is not None:
            self.linger_timer = close_lingering(self.transport, self.eof)

    def _cancel_timers(self) -> None:
        for timer in (self.yield_timer, self.partial_timer, self.linger_timer):
            if timer is not None:
                timer.cancel()
        self.yield_timer = self.partial_timer = self.linger_timer = None

    def shutdown(self) -> None:
        """The program is stopping: answer what was read, then close."""
        if self.closing:
            return
        waited = self.pending is not None
        self._write([replies.SHUTTING_DOWN] * (waited + self._unanswered(self.backlog)))
        self.backlog = []
        if self.pending is not None:
            self.pending.cancel()
        self._close()

    def _unanswered(self, rest: Sequence[Line]) -> int:
        """How many of ``rest`` and the complete lines still buffered would get a reply."""
        return sum(map(is_command, chain(rest, self.framer.complete())))


_TURN_CHECK = 32  # lines between looks at the clock
