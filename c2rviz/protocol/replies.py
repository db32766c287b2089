"""Every reply text the server sends, in one place (the tests import these too).

A reply is one line that starts with ``ok`` or ``error:``. Functions here return
the line without its newline; the server adds ``\\n``.
"""

from __future__ import annotations

from collections.abc import Iterable

from ..errors import limit_text
from .registry import help_text

OK = "ok"
BYE = "ok bye"
SHUTTING_DOWN = "error: server is shutting down"
NOT_UTF8 = "line is not valid UTF-8"


def help_reply() -> str:
    """The ``help`` reply: every verb of the registry and its arguments."""
    return "ok commands: " + help_text()


def ok(payload: str) -> str:
    """An ``ok`` reply carrying ``payload``."""
    return f"ok {payload}"


def error(problem: object) -> str:
    """An ``error:`` reply; ``problem`` is usually a ``C2rvizError``."""
    return f"error: {problem}"


def numbers(values: Iterable[float]) -> str:
    """Comma-separated values, 10 significant digits, no trailing zeros.

    Values within 1e-9 of zero (in their own unit: [m], [rad] or [deg]) print as
    ``0``, and so does ``-0.0``: forward kinematics leaves rounding noise such as
    ``-5.4e-12`` m or ``-3.1e-10`` deg where the answer is 0, and a reply
    of ``0`` says what is meant. 1e-9 is far below anything a robot resolves (a
    nanometre, a nanoradian) and far above double-precision noise on values of
    order 1 to 360.
    """
    return ",".join([f"{value:.10g}" if abs(value) > 1e-9 else "0" for value in values])


def pairs(colliding: Iterable[tuple[str, str]]) -> str:
    """Colliding pairs as ``a~b,c~d``, or ``none``."""
    return ",".join(f"{a}~{b}" for a, b in colliding) or "none"


def limit(value: float) -> str:
    """One joint limit as ``limits``, limit errors and the page print it.

    Args:
        value: The limit in the unit shown ([rad], [deg] or [m]).

    Returns:
        10 significant digits, no trailing zeros (``-89.9999999``, ``3.1416``);
        ``0`` within 1e-9 of zero. A value printed this way and sent back is
        within the limit's tolerance (``errors.within_limit``).
    """
    return limit_text(value)


def too_many_clients(limit: int) -> str:
    return f"error: too many clients (limit {limit}); closing"


def incomplete_line(timeout_s: float) -> str:
    return f"error: line left incomplete for {timeout_s:g} s; closing"


def unread_replies(limit: int) -> str:
    return f"error: over {limit} bytes of unread replies; closing"


def not_http(viewer_url: str | None) -> bytes:
    """The whole answer to an HTTP request on the command port: a 400 a browser shows.

    Its body is one ``error:`` line (so a line client reads it as one too) saying
    what the port is and where the viewer is (``viewer_url``; None: no viewer).
    """
    viewer = f"the viewer is at {viewer_url}" if viewer_url else "no viewer is running"
    body = (
        f"error: this is the c2rviz command port (one text command per line), not HTTP; {viewer}\n"
    ).encode()
    head = (
        "HTTP/1.1 400 Bad Request\r\n"
        "Content-Type: text/plain; charset=utf-8\r\n"
        f"Content-Length: {len(body)}\r\n"
        "Connection: close\r\n\r\n"
    )
    return head.encode() + body
