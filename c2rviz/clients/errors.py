"""What can go wrong on the client side of the wire, one class each, and the checks of a
client method's arguments that raise them before anything is sent.

Every class is a ``C2rvizError``; those that are also a built-in kind say so
(``ConnectionLost`` is a ``ConnectionError``, a wrong argument's type a ``TypeError``),
so a controller may catch either. ``ServerUnavailable`` (no server to connect to) is in
``connection``.

Each check (``number``, ``values``, ``indices``, ``word``, ``choice``, ``flag``) names the
method and the argument (``ArgumentTypeError`` for a wrong type, ``ArgumentError`` for a
wrong count or value). Numbers are written in their shortest exact form (``repr``,
``numbers_text``), so the server reads exactly the value given.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Iterable, Sequence

from ..errors import C2rvizError, shown


class CommandError(C2rvizError):
    """The server refused a command: its ``error:`` reply.

    Attributes:
        command: The line sent.
        message: The server's message (the reply without ``error: ``).
        reply: The whole reply.
    """

    def __init__(self, command: str, reply: str) -> None:
        self.command = command
        self.reply = reply
        self.message = reply.removeprefix("error:").strip()
        super().__init__(self.message)


class ConnectionLost(C2rvizError, ConnectionError):
    """The server closed the connection (it stopped, restarted or dropped us).

    Attributes:
        host, port: The server.
        command: The last line sent, whose reply never came (None: none was waiting).
    """

    def __init__(self, host: str, port: int, command: str | None = None) -> None:
        self.host = host
        self.port = port
        self.command = command
        during = f" while waiting for the reply to {shown(command, 60)}" if command else ""
        super().__init__(
            f"connection to {host}:{port} lost{during} (the server stopped or restarted)"
        )


class ServerShutdown(ConnectionLost, CommandError):  # type: ignore[misc]  # command: str here
    """The server stopped while the command waited (it replied ``error: server is shutting
    down`` and closed): a ``ConnectionLost`` (the server went away mid-call), and a
    ``CommandError`` too, for code that catches the reply.

    Attributes:
        host, port, command: As ``ConnectionLost``'s.
        reply, message: As ``CommandError``'s.
    """

    def __init__(self, host: str, port: int, command: str, reply: str) -> None:
        self.host = host
        self.port = port
        self.command = command
        self.reply = reply
        self.message = reply.removeprefix("error:").strip()
        C2rvizError.__init__(  # not the parents' own: their arguments differ
            self,
            f"connection to {host}:{port} lost while waiting for the reply to "
            f"{shown(command, 60)} (the server is shutting down)",
        )


class UnexpectedReply(C2rvizError):
    """A reply that is not what a c2rviz server answers to the command sent.

    Attributes:
        command: The line sent.
        reply: What came back (cut to 80 characters in the message).
    """

    def __init__(self, command: str, reply: str, what: str = "") -> None:
        self.command = command
        self.reply = reply
        said = what or f"the reply {shown(reply, 80)}"
        super().__init__(
            f"unexpected reply to {shown(command, 40)}: {said} is not a c2rviz reply "
            "(is the port a c2rviz command port?)"
        )


class ReplyTooLong(UnexpectedReply):
    """A reply longer than the client's limit: the connection is closed (the server
    streams without newlines, or is not a c2rviz server)."""

    def __init__(self, command: str, limit: int) -> None:
        self.limit = limit
        super().__init__(command, "", f"a line over the client's limit of {limit} bytes")


class ReplyTimeout(C2rvizError, TimeoutError):
    """No reply within the client's ``timeout``; the connection is closed (a late reply
    would answer the next command)."""

    def __init__(self, command: str, timeout_s: float) -> None:
        self.command = command
        self.timeout_s = timeout_s
        super().__init__(f"no reply to {shown(command, 60)} within {timeout_s:g} s")


class ArgumentError(C2rvizError, ValueError):
    """A client method was given a value it cannot send; nothing was sent.

    Attributes:
        method: The method (``joints``).
        argument: The argument's name (``values``).
        problem: What is wrong with it.
    """

    def __init__(self, method: str, argument: str, problem: str) -> None:
        self.method = method
        self.argument = argument
        self.problem = problem
        super().__init__(f"{method}({argument}=...): {problem}; nothing was sent")


class ArgumentTypeError(ArgumentError, TypeError):
    """A client method's argument of the wrong type; nothing was sent."""


def number(method: str, argument: str, value: object) -> float:
    """``value`` as a finite float: an int or float (numpy's too), not a bool or a string."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ArgumentTypeError(method, argument, f"expected a number, got {_kind(value)}")
    result = float(value)
    if not math.isfinite(result):
        raise ArgumentError(method, argument, f"{result} is not a finite number")
    return result


def values(
    method: str, argument: str, given: object, count: int | None = None
) -> tuple[float, ...]:
    """``given`` as finite floats: a sequence (or other iterable) of numbers, not a string.

    Args:
        count: How many there must be (None: any number, at least one).
    """
    if isinstance(given, (str, bytes)) or not isinstance(given, Iterable):
        raise ArgumentTypeError(
            method, argument, f"expected a sequence of numbers, got {_kind(given)}"
        )
    items = list(given)
    out = []
    for i, item in enumerate(items):
        if isinstance(item, bool) or not isinstance(item, numbers.Real):
            raise ArgumentTypeError(method, argument, f"item {i} is {_kind(item)}, not a number")
        value = float(item)
        if not math.isfinite(value):
            raise ArgumentError(method, argument, f"item {i} ({value}) is not a finite number")
        out.append(value)
    if count is not None and len(out) != count:
        raise ArgumentError(method, argument, f"needs {count} values, got {len(out)}")
    if not out:
        raise ArgumentError(method, argument, "needs at least one value")
    return tuple(out)


def indices(method: str, argument: str, given: object) -> tuple[int, ...]:
    """``given`` as joint indices: a sequence of ints >= 0 (or one int)."""
    items = [given] if isinstance(given, int) and not isinstance(given, bool) else given
    if isinstance(items, (str, bytes)) or not isinstance(items, Iterable):
        raise ArgumentTypeError(method, argument, f"expected joint indices, got {_kind(given)}")
    out = []
    for i, item in enumerate(items):
        if isinstance(item, bool) or not isinstance(item, numbers.Integral):
            raise ArgumentTypeError(method, argument, f"item {i} is {_kind(item)}, not an int")
        if item < 0:
            raise ArgumentError(method, argument, f"item {i} ({item}) is below 0")
        out.append(int(item))
    if not out:
        raise ArgumentError(method, argument, "needs at least one index")
    return tuple(out)


def word(method: str, argument: str, given: object) -> str:
    """``given`` as one word: a non-empty string without spaces or control characters."""
    if not isinstance(given, str):
        raise ArgumentTypeError(method, argument, f"expected a string, got {_kind(given)}")
    if not given or not given.isascii() or not given.isprintable() or " " in given:
        raise ArgumentError(method, argument, f"{given!r} is not one plain word")
    if "#" in given:
        raise ArgumentError(method, argument, f"{given!r} has a '#' (a comment would start)")
    return given


def choice(method: str, argument: str, given: object, choices: Sequence[str]) -> str:
    """``given``, one of ``choices`` (lower case)."""
    text = word(method, argument, given).lower()
    if text not in choices:
        raise ArgumentError(method, argument, f"{given!r} is not one of {', '.join(choices)}")
    return text


def flag(method: str, argument: str, given: object) -> bool:
    """``given`` as a bool (True or False only)."""
    if not isinstance(given, bool):
        raise ArgumentTypeError(method, argument, f"expected True or False, got {_kind(given)}")
    return given


def numbers_text(items: Iterable[float]) -> str:
    """Values as the protocol writes a list: comma-separated, each exact."""
    return ",".join(map(repr, items))


def _kind(value: object) -> str:
    if isinstance(value, str):
        return f"a string ({value[:20]!r})"
    return f"{type(value).__name__}"
