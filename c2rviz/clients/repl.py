"""``c2rviz-cli``: the interactive command line (the seed's ``socketcmdline.py``).

Every line is sent to the server and its reply printed; a few words are local
to this client, as in the seed: ``file``, ``sleep``, ``where``, ``goto``,
``watch``, ``help``, ``q`` and ``quit`` (``repl_local``; this module is the
loop that reads lines, and the program's flags). The connection's unit mode is tracked from the
``degrees``/``radians`` replies (``Client.degrees``), so ``goto`` and
``where`` speak the units the user chose, and a reconnect restores them.

On a terminal there is a ``> `` prompt with line editing and history
(``~/.c2rviz_history``, or ``$C2RVIZ_HISTORY``), and ``where`` prints a table of
joint names and values; with piped input there is no prompt, ``where`` gets the
server's own reply, the replies go to stdout and the connection messages to stderr.
The server's text is printed with control characters escaped (``stream.shown``), and a
reply longer than the client's limit closes the connection rather than fill memory
(``lines.LineClient``).

Exit status: 0 left with ``q``, ``quit``, Ctrl-D or Ctrl-C at the prompt; 1 no
server (after retrying ``--timeout`` seconds), or, with piped input, a line got
an ``error:`` (the rest still ran, as typed); 2 bad options or config.
"""

from __future__ import annotations

import argparse
import contextlib
import math
import os
import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TextIO

from ..errors import C2rvizError
from ..protocol.registry import usages
from .client import Client
from .connection import ServerUnavailable, add_connection_args, server_address
from .errors import CommandError, UnexpectedReply
from .repl_local import LOCAL_USAGE, LocalCommands
from .stream import watch_main


class Repl(LocalCommands):
    """Reads lines, runs the local words, sends the rest, prints the replies."""

    def __init__(
        self,
        client: Client,
        *,
        out: TextIO,
        info: TextIO,
        interactive: bool,
        step: float | None = None,
        rate_hz: float = 50.0,
        speed: float = 1.0,
        config: str | None = None,
    ) -> None:
        """Args:
        client: The connection (not yet open).
        out: Replies and results.
        info: Connection messages.
        interactive: Prompt with ``> `` and read with ``input`` (readline).
        step: Largest ``goto`` step, in the connection's units (default 2 degrees).
        rate_hz: ``goto`` steps per second.
        speed: ``file`` divides sleeps by this.
        config: The ``--config`` ini.
        """
        super().__init__(
            client, out=out, info=info, step=step, rate_hz=rate_hz, speed=speed, config=config
        )
        self.interactive = interactive

    def run(self) -> int:
        """Connect, then read and run lines until the user leaves; return the exit status.

        With piped input the status is 1 when any line got an ``error:``, so a script
        run as ``c2rviz-cli < script`` fails like ``c2rviz-play`` does; a person at
        the prompt has seen each error, and leaving is not a failure.
        """
        client = self.client
        self.say("Socket Created")
        try:
            try:
                names = client.joint_names()
            except (UnexpectedReply, CommandError) as exc:
                self.say(f"c2rviz-cli: {client.host}:{client.port} is not a c2rviz server: {exc}")
                return 1
            self.say(
                f"Socket Connected to {client.host}:{client.port}: {client.robot_name}, "
                f"joints 0..{len(names) - 1} ('help' lists the commands)"
            )
            while True:
                try:
                    line = self._read()
                except (EOFError, KeyboardInterrupt):
                    if self.interactive:
                        self.show("")
                    return self._status()
                try:
                    if not self.handle(line):
                        return self._status()
                except KeyboardInterrupt:
                    self.show("interrupted")
                except ServerUnavailable:
                    raise
                except C2rvizError as exc:
                    self.errors += 1
                    self.show(f"error: {exc}")
        except ServerUnavailable as exc:
            self.say(f"{exc}; giving up")
            return 1
        except KeyboardInterrupt:  # while connecting
            self.say("interrupted")
            return 130

    def _status(self) -> int:
        return 1 if self.errors and not self.interactive else 0

    def _read(self) -> str:
        if self.interactive:
            return input("> ")
        line = sys.stdin.readline()
        if not line:
            raise EOFError
        return line.rstrip("\r\n")

    def handle(self, line: str) -> bool:
        """Run one line; return False when the REPL should end."""
        words = line.split("#", 1)[0].split()
        if not words:
            return True
        verb = words[0].lower()
        if verb not in ("q", "sleep") and self.client.is_open and not self.client.alive():
            self.say(
                f"connection to {self.client.host}:{self.client.port} lost "
                "(the server stopped or restarted); reconnecting"
            )
        local = self.local.get(verb)
        if verb == "where" and not self.interactive:
            local = None  # piped: the server's reply as it is, as any client would see it
        if local is not None and (
            verb in ("file", "sleep", "goto", "watch", "help") or len(words) == 1
        ):
            return local(words[1:])
        reply = self.ask(line)
        self.show(reply)
        if reply.startswith("error"):
            self.errors += 1
        return verb != "bye" or not reply.startswith("ok")


def _setup_readline() -> Callable[[], None] | None:
    """Line editing, completion and history; returns the function that saves history."""
    try:
        import readline
    except ImportError:  # pragma: no cover - not on every platform
        return None
    path = Path(os.environ.get("C2RVIZ_HISTORY") or Path.home() / ".c2rviz_history")
    with contextlib.suppress(OSError):
        readline.read_history_file(path)
    readline.set_history_length(1000)
    words = sorted({*usages(), *LOCAL_USAGE})

    def complete(text: str, state: int) -> str | None:
        if readline.get_begidx() != 0:
            return None
        matches = [w + " " for w in words if w.startswith(text.lower())]
        return matches[state] if state < len(matches) else None

    readline.set_completer(complete)
    readline.parse_and_bind("tab: complete")

    def save() -> None:
        with contextlib.suppress(OSError):
            readline.write_history_file(path)

    return save


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="c2rviz-cli",
        description="Type c2rviz commands; each is sent to the server and its reply printed. "
        "Local commands: " + ", ".join(LOCAL_USAGE) + " ('help' explains them).",
    )
    add = parser.add_argument
    add_connection_args(parser)
    add(
        "--step",
        type=float,
        metavar="S",
        help="largest goto step on a server without motion, in the connection's units "
        "(default 2 degrees)",
    )
    add(
        "--rate",
        type=float,
        default=50.0,
        metavar="HZ",
        help="goto steps per second on a server without motion (50)",
    )
    add("--speed", type=float, default=1.0, metavar="X", help="file: divide sleeps by X (1)")
    add(
        "--watch",
        nargs="?",
        const="",
        metavar="HZ",
        help="print the server's state and event lines (at most HZ states a second; "
        "default its frame rate) until Ctrl-C, instead of reading commands",
    )
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``c2rviz-cli`` / ``clients/socketcmdline.py``; returns the exit status."""
    args = build_parser().parse_args(argv)
    for name in ("step", "rate", "speed"):
        value = getattr(args, name)
        if value is not None and not (value > 0 and math.isfinite(value)):
            print(f"c2rviz-cli: --{name} must be a number > 0", file=sys.stderr)
            return 2
    try:
        host, port = server_address(args.host, args.port, args.config)
    except C2rvizError as exc:
        print(f"c2rviz-cli: {exc}", file=sys.stderr)
        return 2
    if args.watch is not None:
        return watch_main(host, port, args.watch, sys.stdout)
    interactive = sys.stdin.isatty()
    info = sys.stdout if interactive else sys.stderr

    def notify(message: str) -> None:
        print(message, file=info, flush=True)

    client = Client(host, port, retry_s=args.timeout, notify=notify)
    repl = Repl(
        client,
        out=sys.stdout,
        info=info,
        interactive=interactive,
        step=args.step,
        rate_hz=args.rate,
        speed=args.speed,
        config=args.config,
    )
    save_history = _setup_readline() if interactive else None
    try:
        return repl.run()
    finally:
        client.close()
        if save_history is not None:
            save_history()


if __name__ == "__main__":
    sys.exit(main())
