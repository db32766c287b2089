"""Watching the server's ``state`` and ``event`` stream from a client.

``watch_lines`` opens a connection of its own, asks ``watch [HZ]`` and yields
the stream's lines; ``watch_main`` is ``c2rviz-cli --watch``, and the REPL's
local ``watch`` prints the same lines until Ctrl-C.
"""

from __future__ import annotations

import socket
import sys
from collections.abc import Iterator
from typing import TextIO

from ..errors import C2rvizError
from ..protocol.grammar import parse_line
from ..protocol.verbs.observe import Watch
from .client import ServerUnavailable

__all__ = ["watch_lines", "watch_main"]


def watch_lines(host: str, port: int, hz: float | None, degrees: bool) -> Iterator[str]:
    """The ``state`` and ``event`` lines of a new connection that asked ``watch [HZ]``
    (in degrees if ``degrees``), until the server closes it.

    Raises:
        ServerUnavailable: no server at ``host:port``.
        C2rvizError: the server refused ``watch`` (its ``error:`` reply).
    """
    try:
        sock = socket.create_connection((host, port), timeout=5.0)
    except OSError as exc:
        raise ServerUnavailable(host, port, 0.0, exc.strerror or str(exc)) from None
    with sock, sock.makefile("rb") as reader:
        sock.settimeout(None)
        asked = ["degrees"] if degrees else []
        asked.append("watch" if hz is None else f"watch {hz!r}")
        sock.sendall("".join(f"{line}\n" for line in asked).encode())
        for _ in asked:
            reply = reader.readline().decode("utf-8", "replace").rstrip("\r\n")
            if not reply.startswith("ok"):
                raise C2rvizError(reply.removeprefix("error: ") or "the server closed")
        for raw in reader:
            yield raw.decode("utf-8", "replace").rstrip("\r\n")


def watch_main(host: str, port: int, hz: str, out: TextIO) -> int:
    """``c2rviz-cli --watch [HZ]``: print the stream until Ctrl-C (status 0) or until the
    server goes (status 1)."""
    try:
        command = parse_line(f"watch {hz}")
        assert isinstance(command, Watch)
        for line in watch_lines(host, port, command.hz, False):
            print(line, file=out, flush=True)
    except KeyboardInterrupt:
        return 0
    except C2rvizError as exc:
        print(f"c2rviz-cli: {exc}", file=sys.stderr)
        return 1 if isinstance(exc, ServerUnavailable) else 2
    except BrokenPipeError:  # the reader of our output left
        return 0
    print(f"c2rviz-cli: connection to {host}:{port} closed by the server", file=sys.stderr)
    return 1
