"""Reading a ``watch`` stream from a plain-socket client: replies, state and event lines."""

from __future__ import annotations

import re

from support import Client

STATE = re.compile(r"state (\d+\.\d{6}) (\S+)")


NUMBER = r"-?\d+(?:\.\d+)?(?:e[+-]?\d+)?"


EVENT = re.compile(
    r"event (arrived|stopped|clear|dropped \d+|marker \S+ \w+ \S+|record-stopped .+"
    r"|collision \S+|grasped \S+|released \S+|resting \S+ on \S+)"
)


def is_reply(line: str) -> bool:
    return line == "ok" or line.startswith(("ok ", "error: "))


def ask(client: Client, line: str, seen: list[str] | None = None) -> str:
    """Send ``line``; return its reply, keeping the stream lines read meanwhile in ``seen``."""
    client.send(line + "\n")
    return read_reply(client, seen)


def read_reply(client: Client, seen: list[str] | None = None) -> str:
    while True:
        line = client.read_line()
        assert line, "the server closed the connection"
        if is_reply(line):
            return line
        assert STATE.fullmatch(line) or EVENT.fullmatch(line), line
        if seen is not None:
            seen.append(line)


def read_until(client: Client, done, seen: list[str]) -> None:
    """Read stream lines into ``seen`` until ``done(line)``."""
    while True:
        line = client.read_line()
        assert line, "the server closed the connection"
        seen.append(line)
        if done(line):
            return


def states(lines: list[str]) -> list[tuple[float, list[float]]]:
    out = []
    for line in lines:
        if m := STATE.fullmatch(line):
            out.append((float(m.group(1)), [float(v) for v in m.group(2).split(",")]))
    return out
