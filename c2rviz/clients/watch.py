"""Watching the server's ``state`` and ``event`` stream from the command line.

``watch_lines`` opens a connection of its own (``stream.WatchStream``), asks
``watch [HZ]`` and yields the stream's lines; ``watch_main`` is ``c2rviz-cli --watch``,
and the REPL's local ``watch`` prints the same lines until Ctrl-C. Lines are printed
with control characters escaped (``display.shown``).
"""

from __future__ import annotations

import sys
from collections.abc import Iterator
from typing import TextIO

from ..errors import C2rvizError
from ..protocol.grammar import parse_line
from ..protocol.verbs.observe import Watch
from .connect import ServerUnavailable
from .display import shown
from .stream import WatchStream

__all__ = ["watch_lines", "watch_main"]


def watch_lines(
    host: str, port: int, hz: float | None, degrees: bool, robot: str | None = None
) -> Iterator[str]:
    """The ``state`` and ``event`` lines of a new connection that asked ``watch [HZ]``
    (in degrees if ``degrees``; of ``robot`` of a cell if given), until the server closes it.

    Raises:
        ServerUnavailable: no server at ``host:port``.
        C2rvizError: the server refused ``watch`` (its ``error:`` reply).
    """
    with WatchStream(host, port, hz, degrees=degrees, robot=robot) as stream:
        yield from stream.lines()


def watch_main(host: str, port: int, hz: str, out: TextIO) -> int:
    """``c2rviz-cli --watch [HZ]``: print the stream until Ctrl-C (status 0) or until the
    server goes (status 1)."""
    try:
        command = parse_line(f"watch {hz}")
        assert isinstance(command, Watch)
        for line in watch_lines(host, port, command.hz, False):
            print(shown(line), file=out, flush=True)
    except KeyboardInterrupt:
        return 0
    except C2rvizError as exc:
        print(f"c2rviz-cli: {shown(str(exc))}", file=sys.stderr)
        return 1 if isinstance(exc, (ServerUnavailable, ConnectionError)) else 2
    except BrokenPipeError:  # the reader of our output left
        return 0
    print(f"c2rviz-cli: connection to {host}:{port} closed by the server", file=sys.stderr)
    return 1
