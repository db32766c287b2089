"""Line clients: request/reply of any command, a bystander process, figures with load.

``loadgen`` measures ``ok``-only commands at full speed; round 2 asks questions
(``where``, ``status``, ``ik``, ``pose``) whose replies carry values, so this
module adds a blocking line client that returns the reply and its round trip,
and a *bystander*: a separate process doing request/reply for a while, so its
round trips are not slowed by this process's own threads (the GIL).

Run as a script it is that bystander:
``python benchmarks/line_clients.py HOST PORT SECONDS LINE`` prints one JSON list of
round trips [s] (plus ``-1`` for each reply that was not ``ok ...``).
"""

from __future__ import annotations

import gc
import itertools
import json
import os
import socket
import statistics
import subprocess
import sys
import threading
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

__all__ = [
    "Bystander",
    "Figure",
    "LineClient",
    "load1",
    "percentile",
    "round_trips",
]

HERE = Path(__file__).resolve().parent


def percentile(values: Sequence[float], q: float) -> float:
    """The ``q``-th percentile (nearest rank) of ``values``."""
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(q / 100 * len(ordered)))]


def load1() -> float:
    """The machine's 1-minute load average now (shared with other work)."""
    return os.getloadavg()[0]


@dataclass
class Figure:
    """One measured figure and the machine's load average when it was taken."""

    value: float
    load: float = field(default_factory=load1)


class LineClient:
    """One blocking TCP connection that sends a line and reads one reply line."""

    def __init__(self, address: tuple[str, int], timeout_s: float = 60.0) -> None:
        self.sock = socket.create_connection(address, timeout=timeout_s)
        self.sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        self._buffer = b""

    def send(self, line: str) -> float:
        """Send ``line``; return when it was sent (``time.perf_counter``)."""
        sent = time.perf_counter()
        self.sock.sendall(line.encode() + b"\n")
        return sent

    def read(self) -> tuple[str, float]:
        """The next reply line (without its newline) and when it was complete."""
        while b"\n" not in self._buffer:
            chunk = self.sock.recv(65536)
            if not chunk:
                raise RuntimeError("server closed the connection")
            self._buffer += chunk
        now = time.perf_counter()
        line, self._buffer = self._buffer.split(b"\n", 1)
        return line.decode(), now

    def ask(self, line: str) -> tuple[str, float]:
        """Send ``line``, wait for its reply; return the reply and the round trip [s]."""
        sent = self.send(line)
        reply, got = self.read()
        return reply, got - sent

    def ok(self, line: str) -> str:
        """``ask`` that insists on an ``ok`` reply; returns what follows ``ok``."""
        reply, _ = self.ask(line)
        if not reply.startswith("ok"):
            raise RuntimeError(f"{line!r} was refused: {reply!r}")
        return reply[2:].strip()

    def close(self) -> None:
        self.sock.close()


def round_trips(
    client: LineClient, lines: Sequence[str], count: int, until: float | None = None
) -> tuple[list[float], int]:
    """Request/reply ``count`` times (or until ``until``, ``time.perf_counter``).

    ``gc`` is off while timing; ``count // 10`` unrecorded warm-up round trips go first.

    Returns:
        The round trips [s], and how many replies were not ``ok ...``.
    """
    cycle = itertools.cycle(lines)
    times: list[float] = []
    refused = 0
    gc.collect()
    gc.disable()
    try:
        for k in range(count // 10 + count):
            reply, seconds = client.ask(next(cycle))
            if not reply.startswith("ok"):
                refused += 1
            if k >= count // 10:
                times.append(seconds)
            if until is not None and time.perf_counter() >= until:
                break
    finally:
        gc.enable()
    return times, refused


class Bystander:
    """A separate process doing request/reply of ``line`` for ``seconds``."""

    def __init__(self, address: tuple[str, int], seconds: float, line: str) -> None:
        argv = [sys.executable, str(HERE / "line_clients.py"), address[0], str(address[1])]
        self.popen = subprocess.Popen(
            [*argv, f"{seconds:g}", line], stdout=subprocess.PIPE, text=True
        )
        self._out = ""
        # Read as it writes: its output is larger than a pipe's buffer.
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()

    def _read(self) -> None:
        self._out, _ = self.popen.communicate()

    def running(self) -> bool:
        return self._reader.is_alive()

    def result(self) -> tuple[list[float], int]:
        """Wait for it; return its round trips [s] and how many were refused."""
        self._reader.join(timeout=600)
        if self.popen.returncode:
            raise RuntimeError(f"bystander failed ({self.popen.returncode})")
        values = json.loads(self._out)
        return [v for v in values if v >= 0], sum(1 for v in values if v < 0)


def _bystander(argv: Sequence[str]) -> int:
    host, port, seconds, line = argv
    client = LineClient((host, int(port)))
    end = time.perf_counter() + float(seconds)
    times: list[float] = []
    gc.disable()
    while time.perf_counter() < end:
        reply, rtt = client.ask(line)
        times.append(rtt if reply.startswith("ok") else -1.0)
    client.close()
    print(json.dumps(times[len(times) // 20 :]))  # the first 5 %: warm-up
    return 0


def summary(values: Sequence[float]) -> str:
    """``median (min..max)`` of ``values``, for log lines."""
    return f"{statistics.median(values):.4g} ({min(values):.4g}..{max(values):.4g})"


if __name__ == "__main__":
    sys.exit(_bystander(sys.argv[1:]))
