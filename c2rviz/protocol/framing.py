"""The line framer: bytes in, complete lines (or why a line is not one) out. No I/O.

A stream of the text protocol is lines ended by ``\\n`` (a ``\\r`` before it is
the line's own; the parser drops it). The framer keeps what has arrived, hands
out the complete lines one batch at a time (at most ``batch_bytes`` of them, so a
client that sends thousands of lines at once gets one batch per turn), and says
when the unfinished line is longer than ``max_line``. A line that is not UTF-8 or
is too long comes out as the ``LineError`` that says so, in its place, and
nothing after a too-long line comes out (the connection closes there).

Both sides use it: the server's TCP door drives it from asyncio, and the clients
read replies through it with the same limit.
"""

from __future__ import annotations

from collections.abc import Sequence

from ..errors import C2rvizError, LineError, LineTooLong
from . import replies

Line = str | C2rvizError
"""A decoded line (without its ``\\n``), or why it could not be one."""

BATCH_BYTES = 8192
"""Complete lines handed out per batch [bytes]. The text port answers a batch with one
write, and the write is where viser's thread gets the interpreter's lock: 64 KiB batches
cost a pipelining client ~10% less CPU but the page 20-30% of its frames during a flood
(issue 40, docs/benchmarks.md), so they stay at 8 KiB while the page shares the process."""


class LineFramer:
    """The bytes of one stream, cut into lines.

    Attributes:
        max_line: Longest line [bytes, without its ``\\n``].
        batch_bytes: Most bytes of complete lines per ``take``.
        buffer: What has arrived and is not yet taken.
    """

    def __init__(self, max_line: int, batch_bytes: int = BATCH_BYTES) -> None:
        self.max_line = max_line
        self.batch_bytes = batch_bytes
        self.buffer = b""

    def feed(self, data: bytes) -> None:
        """``data`` arrived."""
        self.buffer = self.buffer + data if self.buffer else data

    def take(self) -> Sequence[Line] | None:
        """The next batch of complete lines, in order (None: no complete line yet)."""
        buffer = self.buffer
        cut = buffer.rfind(b"\n", 0, self.batch_bytes)
        if cut < 0:
            cut = buffer.find(b"\n")  # the first line is longer than a batch
            if cut < 0:
                return None
        self.buffer = buffer[cut + 1 :]
        return self.decode(buffer[:cut])

    @property
    def has_line(self) -> bool:
        """A complete line is waiting."""
        return b"\n" in self.buffer

    @property
    def too_long(self) -> bool:
        """The unfinished line is already longer than ``max_line``."""
        return len(self.buffer) > self.max_line and b"\n" not in self.buffer

    def rest(self) -> Sequence[Line]:
        """Everything left, the unfinished last line included (the stream has ended: a last
        line without its ``\\n`` is a line too). Empties the buffer."""
        buffer, self.buffer = self.buffer, b""
        return self.decode(buffer) if buffer else []

    def complete(self) -> Sequence[Line]:
        """The complete lines waiting, without taking them (what a shutdown answers)."""
        cut = self.buffer.rfind(b"\n")
        return self.decode(self.buffer[:cut]) if cut >= 0 else []

    def clear(self) -> None:
        self.buffer = b""

    def decode(self, complete: bytes) -> Sequence[Line]:
        """Split ``\\n``-separated lines; mark the undecodable and the over-long ones."""
        max_line = self.max_line
        if complete.isascii():  # the usual case: one decode and one split for the batch
            split = complete.decode("ascii").split("\n")
            if len(complete) <= max_line or max(map(len, split)) <= max_line:
                return split
        elif len(complete) <= max_line:
            try:
                return complete.decode().split("\n")
            except UnicodeDecodeError:
                pass
        lines: list[Line] = []
        for raw in complete.split(b"\n"):
            if len(raw) > max_line:
                lines.append(LineTooLong(max_line))
                break  # the connection closes here; nothing after it runs
            try:
                lines.append(raw.decode())
            except UnicodeDecodeError:
                lines.append(LineError(replies.NOT_UTF8))
        return lines
