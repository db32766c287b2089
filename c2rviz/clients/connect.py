"""Opening a connection to the command server, retrying while it is not up yet.

The server may be starting or restarting when a client begins: ``dial`` retries
a refused connection with a growing delay (0.05 s doubling to 1 s) for up to
``retry_s`` seconds, says once that it is waiting, and then gives up with
``ServerUnavailable``.
"""

from __future__ import annotations

import socket
import time
from collections.abc import Callable

from ..errors import C2rvizError

__all__ = ["ServerUnavailable", "dial"]

_FIRST_DELAY_S = 0.05
_MAX_DELAY_S = 1.0


class ServerUnavailable(C2rvizError):
    """No server answered at ``host:port`` within the retry time."""

    def __init__(self, host: str, port: int, waited_s: float, reason: str) -> None:
        self.host = host
        self.port = port
        self.waited_s = waited_s
        self.reason = reason
        super().__init__(
            f"no c2rviz server at {host}:{port} after {waited_s:.1f} s ({reason}); "
            "start one with `c2rviz`, or give --host/--port"
        )


def _reason(exc: OSError) -> str:
    return exc.strerror or str(exc) or type(exc).__name__


def dial(
    host: str, port: int, retry_s: float, notify: Callable[[str], None] | None = None
) -> socket.socket:
    """A blocking TCP connection to ``host:port`` (no timeout, no Nagle delay).

    Args:
        host, port: The command server.
        retry_s: How long to keep retrying a refused connection [s].
        notify: Called once with a short message when retrying begins.

    Raises:
        ServerUnavailable: nothing accepted the connection in time, or the host
            name does not resolve.
    """
    start = time.monotonic()
    deadline = start + retry_s
    delay = _FIRST_DELAY_S
    told = False
    while True:
        try:
            sock = socket.create_connection((host, port), timeout=5.0)
            break
        except socket.gaierror as exc:  # a bad host name does not get better
            raise ServerUnavailable(host, port, 0.0, _reason(exc)) from None
        except OSError as exc:
            left = deadline - time.monotonic()
            if left <= 0:
                waited = time.monotonic() - start
                raise ServerUnavailable(host, port, waited, _reason(exc)) from None
            if not told and notify is not None:
                notify(
                    f"no server at {host}:{port} yet ({_reason(exc)}); "
                    f"retrying for up to {retry_s:g} s"
                )
                told = True
            time.sleep(min(delay, left))
            delay = min(delay * 2, _MAX_DELAY_S)
    sock.settimeout(None)  # a reply may follow a long server-side sleep
    sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
    return sock
