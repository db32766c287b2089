"""``c2rviz-cli``: the interactive command line (the seed's ``socketcmdline.py``).

Every line is sent to the server and its reply printed; a few words are local
to this client, as in the seed: ``file``, ``sleep``, ``where``, ``goto``,
``help``, ``q`` and ``quit``. The connection's unit mode is tracked from the
``degrees``/``radians`` replies (``Client.degrees``), so ``goto`` and
``where`` speak the units the user chose, and a reconnect restores them.

On a terminal there is a ``> `` prompt with line editing and history
(``~/.c2rviz_history``, or ``$C2RVIZ_HISTORY``); with piped input there is no
prompt, the replies go to stdout and the connection messages to stderr.

Exit status: 0 left with ``q``, ``quit``, Ctrl-D or Ctrl-C at the prompt; 1 no
server (after retrying ``--timeout`` seconds), or, with piped input, a line got
an ``error:`` (the rest still ran, as typed); 2 bad options or config.
"""

from __future__ import annotations

import argparse
import contextlib
import math
import os
import socket
import sys
import time
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import TextIO

from .client import (
    Client,
    ConnectionLost,
    ServerUnavailable,
    add_connection_args,
    find_script,
    server_address,
)
from .commands import USAGE, Joints, Sleep, parse_line
from .errors import BadArguments, C2rvizError, JointCountError, JointLimitError
from .lang.record import Watch
from .player import Progress, play
from .script import check_robot, load_script, robot_mismatch
from .tolerance import within_limit

__all__ = ["LOCAL_USAGE", "Repl", "build_parser", "main", "watch_lines"]

LOCAL_USAGE = {
    "file": ("file NAME [speed=X]", "play a command file (here, else commands/); X divides sleeps"),
    "sleep": ("sleep S", "wait S seconds here"),
    "where": ("where", "joint names and values, in this connection's units"),
    "goto": ("goto v0,...,vn-1 [step=S] [rate=HZ]", "move there smoothly in small joints steps"),
    "watch": ("watch [HZ]", "print the server's state and event lines until Ctrl-C"),
    "help": ("help", "this list"),
    "q": ("q", "leave (the server keeps running)"),
    "quit": ("quit", "stop the server, then leave"),
}
DEFAULT_STEP_DEG = 2.0


def _options(verb: str, words: list[str], allowed: Sequence[str]) -> tuple[list[str], dict]:
    """Split ``key=value`` words (positive numbers) from the rest."""
    usage = LOCAL_USAGE[verb][0]
    rest, options = [], {}
    for word in words:
        key, eq, text = word.partition("=")
        if not eq:
            rest.append(word)
            continue
        if key not in allowed:
            raise BadArguments(verb, f"unknown option {key!r}", usage)
        try:
            value = float(text)
        except ValueError:
            value = math.nan
        if not (value > 0 and math.isfinite(value)):
            raise BadArguments(verb, f"{key} must be a number > 0, got {text!r}", usage)
        options[key] = value
    return rest, options


class Repl:
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
    ) -> None:
        """Args:
        client: The connection (not yet open).
        out: Replies and results.
        info: Connection messages.
        interactive: Prompt with ``> `` and read with ``input`` (readline).
        step: Largest ``goto`` step, in the connection's units (default 2 degrees).
        rate_hz: ``goto`` steps per second.
        speed: ``file`` divides sleeps by this.
        """
        self.client = client
        self.out = out
        self.info = info
        self.interactive = interactive
        self.step = step
        self.rate_hz = rate_hz
        self.speed = speed
        self.errors = 0
        """Lines that got an ``error:`` (from the server or from this client)."""
        self._local: dict[str, Callable[[list[str]], bool]] = {
            "file": self._file,
            "sleep": self._sleep,
            "where": self._where,
            "goto": self._goto,
            "watch": self._watch,
            "help": self._help,
            "q": lambda words: False,
            "quit": self._quit,
        }

    def say(self, message: str) -> None:
        print(message, file=self.info, flush=True)

    def show(self, message: str) -> None:
        print(message, file=self.out, flush=True)

    def run(self) -> int:
        """Connect, then read and run lines until the user leaves; return the exit status.

        With piped input the status is 1 when any line got an ``error:``, so a script
        run as ``c2rviz-cli < script`` fails like ``c2rviz-play`` does; a person at
        the prompt has seen each error, and leaving is not a failure.
        """
        client = self.client
        self.say("Socket Created")
        try:
            names = client.joint_names()
            self.say(
                f"Socket Connected to {client.host}:{client.port}: {client.robot}, "
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
        local = self._local.get(verb)
        if local is not None and (verb in ("file", "sleep", "goto", "watch") or len(words) == 1):
            return local(words[1:])
        reply = self.ask(line)
        self.show(reply)
        if reply.startswith("error"):
            self.errors += 1
        return verb != "bye" or not reply.startswith("ok")

    def ask(self, line: str) -> str:
        """Send ``line``; if the connection was lost, reconnect and send it once more."""
        try:
            return self.client.ask(line)
        except ConnectionLost as exc:
            self.say(f"{exc}; reconnecting")
        return self.client.ask(line)

    # local commands

    def _file(self, words: list[str]) -> bool:
        rest, options = _options("file", words, ["speed"])
        if len(rest) != 1:
            raise BadArguments("file", "needs one file name", LOCAL_USAGE["file"][0])
        try:
            script = load_script(find_script(rest[0]), rest[0])
        except OSError as exc:
            raise C2rvizError(f"file: {exc}") from None
        client = self.client
        names = client.joint_names()
        mismatch = robot_mismatch(script, client.robot or "?", names)
        if mismatch is not None:
            self.say(f"warning: {mismatch}; playing it anyway")
        problems = script.problems or check_robot(script, client.robot or "?", names)
        for problem in problems:
            self.show(problem)
        if problems:
            self.errors += 1
            self.show(f"{script.name}: nothing was sent")
            return True
        show = Progress(self.out, self.out, in_place=False)
        try:
            errors = play(client, script, show, speed=options.get("speed", self.speed))
        except ConnectionLost:
            self.errors += 1
            return True  # play has said where it stopped; the next command reconnects
        self.errors += errors > 0
        if not errors:
            self.show(f"{script.name}: {len(script.lines)} commands, all ok")
        return True

    def _sleep(self, words: list[str]) -> bool:
        command = parse_line(" ".join(["sleep", *words]))
        assert isinstance(command, Sleep)
        time.sleep(command.seconds)
        return True

    def _where(self, words: list[str]) -> bool:
        names = self.client.joint_names()
        values = self.client.where()
        unit = "degrees" if self.client.degrees else "radians"
        self.show(f"{self.client.robot} ({unit}):")
        width = max(map(len, names))
        for i, (name, value) in enumerate(zip(names, values)):
            self.show(f"  {i}  {name:<{width}}  {value:.10g}")
        return True

    def _goto(self, words: list[str]) -> bool:
        usage = LOCAL_USAGE["goto"][0]
        rest, options = _options("goto", words, ["step", "rate"])
        try:
            command = parse_line(" ".join(["joints", *rest]))
        except BadArguments as exc:
            raise BadArguments("goto", exc.problem, usage) from None
        assert isinstance(command, Joints)
        target = list(command.values)
        client = self.client
        n = len(client.joint_names())
        if len(target) != n:
            raise BadArguments("goto", str(JointCountError(n, len(target))), usage)
        names = client.joint_names()
        for i, (value, (lower, upper, unit)) in enumerate(zip(target, client.limits())):
            if not within_limit(value, lower, upper):  # refuse before the first step
                raise BadArguments(
                    "goto", str(JointLimitError(names[i], i, value, lower, upper, unit)), usage
                )
        current = client.where()
        default_step = DEFAULT_STEP_DEG if client.degrees else math.radians(DEFAULT_STEP_DEG)
        step = options.get("step", self.step or default_step)
        period_s = 1.0 / options.get("rate", self.rate_hz)
        distance = max(abs(t - c) for t, c in zip(target, current))
        steps = max(1, math.ceil(distance / step - 1e-9))
        start = time.monotonic()
        for k in range(1, steps + 1):
            if k > 1:
                time.sleep(max(0.0, start + (k - 1) * period_s - time.monotonic()))
            values = (
                target if k == steps else [c + (t - c) * k / steps for t, c in zip(target, current)]
            )
            reply = client.ask("joints " + ",".join(map(repr, values)))
            if not reply.startswith("ok"):
                self.errors += 1
                self.show(f"goto: stopped at step {k}/{steps}: {reply}")
                return True
        self.show(f"ok (goto: {steps} steps in {time.monotonic() - start:.2f} s)")
        return True

    def _watch(self, words: list[str]) -> bool:
        """Print the stream (on a connection of its own) until Ctrl-C."""
        command = parse_line(" ".join(["watch", *words]))
        assert isinstance(command, Watch)
        client = self.client
        try:
            for line in watch_lines(client.host, client.port, command.hz, client.degrees):
                self.show(line)
        except KeyboardInterrupt:
            return True
        raise ConnectionLost(client.host, client.port)

    def _help(self, words: list[str]) -> bool:
        self.show("local commands (this client):")
        width = max(len(usage) for usage, _ in LOCAL_USAGE.values())
        for usage, what in LOCAL_USAGE.values():
            self.show(f"  {usage:<{width}}  {what}")
        reply = self.ask("help")
        self.show("server commands (sent as typed; # starts a comment):")
        for usage in reply.partition(": ")[2].split("; "):
            # A verb this client handles itself (where, sleep, help, quit) is listed once,
            # above: typed here, it never reaches the server as the server's own verb.
            if usage.split(" ", 1)[0].lower() not in LOCAL_USAGE:
                self.show(f"  {usage}")
        return True

    def _quit(self, words: list[str]) -> bool:
        reply = self.ask("quit")
        self.show(reply)
        self.errors += not reply.startswith("ok")
        return False


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


def _watch_main(host: str, port: int, hz: str, out: TextIO) -> int:
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
    words = sorted({*USAGE, *LOCAL_USAGE})

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
        help="largest goto step, in the connection's units (default 2 degrees)",
    )
    add("--rate", type=float, default=50.0, metavar="HZ", help="goto steps per second (50)")
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
        return _watch_main(host, port, args.watch, sys.stdout)
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
