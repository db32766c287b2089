"""A bounded soak: 20 clients x 2,000 mixed lines at once, checked line by line and at the end.

Clients 0..6 each own one joint and are the only ones that move it (in their own
unit mode, switched now and then); the others send everything else. Every line,
good or bad, is pipelined in batches; each command must get exactly one reply,
the right one, and the final state must be what a simple model predicts.
"""

from __future__ import annotations

import math
import random
import socket
import threading
import time

from c2rviz.errors import LineTooLong
from c2rviz.protocol import replies
from c2rviz.world.observer import MAX_MARKERS

CLIENTS = 20
LINES = 2000
BATCH = 100
MAX_LINE = 1024
OWNERS = 7  # client k < 7 owns joint k
LIMIT_RAD = 1.9  # inside every motoman joint's limits


class Start(str):
    """An expected reply given by its start only."""


class OwnJoint(str):
    """A ``where`` reply whose field ``index`` must read ``value`` (what its owner set)."""

    def __new__(cls, index: int, value: float) -> OwnJoint:
        self = super().__new__(cls, "ok ")
        self.index, self.value = index, replies.numbers([value])
        return self


def matches(reply: str, want: str) -> bool:
    if isinstance(want, OwnJoint):
        return reply.startswith("ok ") and reply[3:].split(",")[want.index] == want.value
    return reply.startswith(want) if isinstance(want, Start) else reply == want


# (line, expected reply): the same for every client in every state.
BAD = [
    (b"move 0 999", Start("error: joint_s (index 0) = 999 ")),  # over in rad and deg
    (b"move 99 1", "error: joint index 99 out of range: motoman_sia20d has joints 0..6"),
    (b"move 0,0 1,2", Start("error: move: joint 0 is given twice")),
    (b"joints 1,2", "error: joints needs 7 values, got 2"),
    (b"joints 0,0,0,0,0,0,nan", Start("error: joints: bad number 'nan'")),
    (b"move 3 1e309", Start("error: move: value '1e309' is not a finite number")),
    (b"jump 1", "error: unknown command 'jump' (try 'help')"),
    (b"home\x00", Start("error: character '\\x00' at column 5")),
    (b"\xff\xfe", "error: " + replies.NOT_UTF8),
    (b"mark 1,2,3", Start("error: mark: needs 6 values, got 3")),
    (b"color 2,0,0", Start("error: color: channel 2 is outside 0..1")),
    (b"sleep -1", Start("error: sleep: seconds must be >= 0, got -1")),
    ("move 0 \u0661".encode(), Start("error: character")),
]
QUIET = [b"", b"   ", b"# a comment", b"\t# another\r"]
ASK = [
    (b"pose", Start("ok ")),
    (b"names", Start("ok motoman_sia20d ")),
    (b"help", replies.help_reply()),
]


def script(k: int) -> tuple[list[bytes], list[str], float | None, int]:
    """Client ``k``'s lines, the reply each command must get (or start with), its joint's
    final value [rad] (None if it owns none) and how many markers it drops."""
    rng = random.Random(k)
    lines: list[bytes] = []
    expected: list[str] = []
    degrees = False
    last: float | None = 0.0 if k < OWNERS else None
    marks = 0
    for _ in range(LINES):
        roll = rng.random()
        if roll < 0.25 and k < OWNERS:
            value_rad = rng.uniform(-LIMIT_RAD, LIMIT_RAD)
            value = math.degrees(value_rad) if degrees else value_rad
            text = f"{value:.9g}"
            lines.append(f"MOVE  {k}\t{text}\r".encode())
            expected.append("ok")
            scale = math.pi / 180.0 if degrees else 1.0
            last = float(text) * scale  # exactly what the session stores
        elif roll < 0.30:
            degrees = not degrees
            lines.append(b"degrees" if degrees else b"radians")
            expected.append("ok")
        elif roll < 0.40:
            lines.append(b"where")
            if k < OWNERS:  # no one else may have moved this client's joint
                scale = math.pi / 180.0 if degrees else 1.0
                expected.append(OwnJoint(k, last / scale))
            else:
                expected.append(Start("ok "))
        elif roll < 0.43:
            lines.append(
                b"mark " + ",".join(["0.5"] * 6).encode() if rng.random() < 0.5 else b"mark"
            )
            expected.append("ok")
            marks += 1
        elif roll < 0.45:
            lines.append(b"sleep 0")
            expected.append("ok")
        elif roll < 0.55:
            line, reply = rng.choice(ASK)
            lines.append(line)
            expected.append(reply)
        elif roll < 0.65:
            lines.append(rng.choice(QUIET))  # no reply
        else:
            line, reply = rng.choice(BAD)
            lines.append(line)
            expected.append(reply)
    return lines, expected, last, marks


def is_command(line: bytes) -> bool:
    text = line.strip()
    return bool(text) and not text.startswith(b"#")


def drive(server, k: int, lines: list[bytes], expected: list[str], problems: list[str]) -> None:
    with (
        socket.create_connection((server.host, server.port), timeout=30) as sock,
        sock.makefile("rb") as stream,  # closed with it: no socket left for the collector
    ):
        wanted = iter(expected)
        for start in range(0, len(lines), BATCH):
            batch = lines[start : start + BATCH]
            sock.sendall(b"".join(line + b"\n" for line in batch))
            for line in filter(is_command, batch):
                reply = stream.readline().decode().rstrip("\n")
                want = next(wanted)
                if not matches(reply, want):
                    problems.append(f"client {k}: {line!r} -> {reply!r}, wanted {want!r}")
                    return
        sock.sendall(b"x" * (MAX_LINE + 1) + b"\nwhere\n")  # ends it: one error, closed
        reply = stream.readline().decode().rstrip("\n")
        if reply != replies.error(LineTooLong(MAX_LINE)) or stream.read() != b"":
            problems.append(f"client {k}: ended with {reply!r}")


def test_twenty_clients_two_thousand_lines_each(start_server, connect):
    server = start_server(max_line=MAX_LINE)
    scripts = [script(k) for k in range(CLIENTS)]
    problems: list[str] = []
    threads = [
        threading.Thread(target=drive, args=(server, k, lines, expected, problems))
        for k, (lines, expected, _last, _marks) in enumerate(scripts)
    ]
    start = time.perf_counter()
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join(timeout=60)
    took = time.perf_counter() - start
    total = sum(len(s[0]) for s in scripts)
    print(f"soak: {CLIENTS} clients, {total} lines in {took:.2f} s ({total / took:,.0f} lines/s)")
    assert not any(thread.is_alive() for thread in threads)
    assert problems == []
    q, markers = server.call(lambda: (server.world.q, len(server.world.markers)))
    assert q == tuple(s[2] for s in scripts[:OWNERS])
    assert markers == min(sum(s[3] for s in scripts), MAX_MARKERS)  # the oldest go first
    assert connect(server).ask("where") == replies.ok(replies.numbers(q))
