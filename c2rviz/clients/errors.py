"""What can go wrong on the client side of the wire, one class each.

Every class is a ``C2rvizError``; those that are also a built-in kind say so
(``ConnectionLost`` is a ``ConnectionError``, a wrong argument's type a ``TypeError``),
so a controller may catch either. ``ServerUnavailable`` (no server to connect to) is in
``connect``.
"""

from __future__ import annotations

from ..errors import C2rvizError, shown

__all__ = [
    "ArgumentError",
    "ArgumentTypeError",
    "CommandError",
    "ConnectionLost",
    "ReplyTimeout",
    "ReplyTooLong",
    "ServerShutdown",
    "UnexpectedReply",
]


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
