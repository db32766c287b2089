"""``c2rviz-play``: check a command file with the server's own parser, then play it.

The whole file is parsed with ``c2rviz.commands.parse_line`` before anything is
sent, so a typo on line 40 is reported as ``file:40: error: ...`` while the
robot is still where it was. Once connected, the joint counts of ``joints``
lines and the indices of ``move`` lines are checked against the server's
robot (``names``), again before the first line is sent; a file that declares
its robot in its opening comments (a ``# robot: NAME`` line) and finds another
one at the server is warned about, or refused with ``--strict``. Then every command
line is sent and its reply shown; the first ``error:`` reply stops the play
(unless ``--keep-going``).

``sleep S`` lines are sent to the server as ``sleep S/speed``: the server
holds that connection's later lines until the pause is over and then replies
``ok``, so timing stays right even when lines are pipelined.

Exit status: 0 every line got ``ok``; 1 a line got an error, or the server
could not be reached or went away; 2 the file or the options are wrong
(nothing was sent); 130 interrupted.
"""

from __future__ import annotations

import argparse
import re
import shutil
import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
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
from .commands import Bye, Command, Joints, Move, Quit, Sleep, parse_line
from .errors import C2rvizError, JointCountError, JointIndexError

__all__ = [
    "Progress",
    "Script",
    "ScriptLine",
    "build_parser",
    "load_script",
    "main",
    "play",
    "robot_mismatch",
]

_ROBOT_HEADER = re.compile(r"#\s*robot:\s*([A-Za-z0-9_.-]+)\s*", re.IGNORECASE)


@dataclass(frozen=True, slots=True)
class ScriptLine:
    """One command line of a file."""

    number: int
    """Line number in the file, from 1."""
    text: str
    """The line as written (without its newline)."""
    command: Command
    wire: str
    """What is sent: the line without its comment and outer spaces."""


@dataclass
class Script:
    """A parsed command file: its command lines and every line that did not parse."""

    name: str
    lines: list[ScriptLine] = field(default_factory=list)
    problems: list[str] = field(default_factory=list)
    """``name:line: error: ...`` for each line the parser rejected."""
    robot: str | None = None
    """The robot the file is written for: its ``# robot: NAME`` line, if it has one."""

    def problem(self, number: int, message: object) -> str:
        return f"{self.name}:{number}: error: {message}"


def load_script(path: Path, name: str | None = None) -> Script:
    """Read and parse a command file (comments and blank lines are dropped).

    The first ``# robot: NAME`` line among the comments that open the file (before
    its first command) names the robot it is written for (``Script.robot``).

    Args:
        path: The file.
        name: How messages name it (default: ``path`` as given).

    Raises:
        OSError: the file cannot be read.
    """
    script = Script(str(path) if name is None else name)
    text = path.read_bytes().decode("utf-8-sig", "replace")
    closed_at: ScriptLine | None = None
    for number, raw in enumerate(text.split("\n"), start=1):
        raw = raw.rstrip("\r")
        try:
            command = parse_line(raw)
        except C2rvizError as exc:
            script.problems.append(script.problem(number, exc))
            continue
        if command is None:
            header = _ROBOT_HEADER.fullmatch(raw.strip())
            if header and script.robot is None and not script.lines and not script.problems:
                script.robot = header.group(1)
            continue
        if closed_at is not None:
            verb = closed_at.wire.split()[0]
            script.problems.append(
                script.problem(
                    number,
                    f"line {closed_at.number} ({verb!r}) closes the connection, "
                    "so this line would never run",
                )
            )
        line = ScriptLine(number, raw, command, raw.split("#", 1)[0].strip())
        if isinstance(command, (Bye, Quit)) and closed_at is None:
            closed_at = line
        script.lines.append(line)
    return script


def check_robot(script: Script, robot: str, joint_names: Sequence[str]) -> list[str]:
    """Problems with ``joints`` counts and ``move`` indices for this robot's chain."""
    n = len(joint_names)
    problems = []
    for line in script.lines:
        command = line.command
        if isinstance(command, Joints) and len(command.values) != n:
            problems.append(script.problem(line.number, JointCountError(n, len(command.values))))
        elif isinstance(command, Move):
            bad = [i for i in command.indices if i >= n]
            if bad:
                problems.append(script.problem(line.number, JointIndexError(bad[0], robot, n)))
    return problems


def robot_mismatch(script: Script, robot: str, joint_names: Sequence[str]) -> str | None:
    """What to say when ``script`` declares another robot than the server's, else None."""
    if script.robot is None or script.robot == robot:
        return None
    return (
        f"{script.name} is written for robot {script.robot} (its '# robot:' line), "
        f"but the server runs {robot} ({len(joint_names)} joints)"
    )


class Progress:
    """Shows each played line and its reply.

    On a terminal (``in_place``) one status line is rewritten in place; replies
    that carry data and every error stay on screen. Otherwise one plain line
    per command.
    """

    def __init__(self, out: TextIO, err: TextIO, in_place: bool | None = None) -> None:
        self.out = out
        self.err = err
        self.in_place = out.isatty() if in_place is None else in_place
        self._dirty = False

    def step(self, label: str, text: str, reply: str) -> None:
        message = f"{label} {text} -> {reply}"
        if not self.in_place:
            print(message, file=self.out, flush=True)
            return
        keep = reply not in ("ok", "ok bye") and not reply.startswith("error")
        width = shutil.get_terminal_size().columns - 1
        shown = message if keep or len(message) <= width else message[: width - 3] + "..."
        self.out.write("\r\x1b[K" + shown + ("\n" if keep else ""))
        self.out.flush()
        self._dirty = not keep

    def error(self, message: str) -> None:
        self.end_line()
        print(message, file=self.err, flush=True)

    def end_line(self) -> None:
        """Finish the in-place line so the next output starts on its own line."""
        if self._dirty:
            self.out.write("\n")
            self.out.flush()
            self._dirty = False


def _wire(line: ScriptLine, speed: float) -> str:
    if isinstance(line.command, Sleep) and speed != 1.0:
        return f"sleep {line.command.seconds / speed!r}"
    return line.wire


def play(
    client: Client,
    script: Script,
    show: Progress,
    *,
    speed: float = 1.0,
    keep_going: bool = False,
    window: int = 1,
    prefix: str = "",
) -> int:
    """Send every line of ``script`` and show its reply; return how many got an error.

    Args:
        client: An open or openable connection with no unread replies.
        script: A script with no ``problems``.
        show: Where lines, replies and errors go.
        speed: Sleeps are divided by this.
        keep_going: Go on after an ``error:`` reply.
        window: Lines sent ahead of their replies (1: wait for each reply).
            After an error, lines already sent have run; their replies are shown.
        prefix: Put before each ``k/n`` label (the loop number).

    Raises:
        ConnectionLost: the server went away (already reported through ``show``).
        KeyboardInterrupt: Ctrl-C (reported through ``show``).
    """
    lines = script.lines
    n = len(lines)
    width = len(str(n))
    sent = done = errors = 0
    stop = n
    try:
        while done < stop:
            while sent < stop and sent - done < window:
                client.send(_wire(lines[sent], speed))
                sent += 1
            reply = client.read_reply()
            line = lines[done]
            done += 1
            show.step(f"[{prefix}{done:>{width}}/{n}]", line.wire, reply)
            if not reply.startswith("ok"):
                errors += 1
                show.error(f"{script.name}:{line.number}: {reply}")
                if not keep_going:
                    stop = sent  # what is already sent has run: show its replies
    except ConnectionLost as exc:
        show.error(script.problem(lines[min(done, n - 1)].number, exc))
        raise
    except KeyboardInterrupt:
        show.error(f"{script.name}:{lines[min(done, n - 1)].number}: interrupted")
        raise
    show.end_line()
    return errors


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="c2rviz-play",
        description="Check a c2rviz command file with the server's parser, then play it: "
        "each line is sent, its reply shown; the first error stops the play.",
        epilog="Exit status: 0 all lines ok; 1 a line got an error or no server; "
        "2 the file does not check (nothing was sent). FILE is looked for here, "
        "then in the project's commands/. A '# robot: NAME' line in the file's "
        "opening comments names the robot it is for.",
    )
    add = parser.add_argument
    add("file", metavar="FILE", help="command file, e.g. commands/motoman.txt")
    add_connection_args(parser)
    add(
        "--speed",
        type=_positive,
        default=1.0,
        metavar="X",
        help="divide every sleep by X (default 1)",
    )
    add("--loop", type=int, default=1, metavar="N", help="play N times; 0: until Ctrl-C")
    add("--keep-going", action="store_true", help="go on after an error reply")
    add("--check", action="store_true", help="only parse the file; do not connect")
    add(
        "--strict",
        action="store_true",
        help="refuse (exit 2) when the file's '# robot: NAME' line names another robot "
        "than the server's (default: warn and play)",
    )
    add(
        "--window",
        type=int,
        default=1,
        metavar="N",
        help="lines sent ahead of their replies (default 1); above 1 is faster, but "
        "after an error the lines already sent have run",
    )
    return parser


def _positive(text: str) -> float:
    value = float(text)
    if not value > 0:
        raise argparse.ArgumentTypeError(f"must be > 0, got {text}")
    return value


def _fail(problems: Sequence[str], name: str, err: TextIO) -> int:
    for problem in problems:
        print(problem, file=err)
    s = "" if len(problems) == 1 else "s"
    print(f"{name}: {len(problems)} problem{s}; nothing was sent", file=err, flush=True)
    return 2


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``c2rviz-play``; returns the exit status."""
    args = build_parser().parse_args(argv)
    out, err = sys.stdout, sys.stderr
    if args.loop < 0 or args.window < 1:
        print("c2rviz-play: --loop must be >= 0 and --window >= 1", file=err)
        return 2
    try:
        path = find_script(args.file)
        script = load_script(path, args.file)
        host, port = server_address(args.host, args.port, args.config)
    except (OSError, C2rvizError) as exc:
        print(f"c2rviz-play: {exc}", file=err)
        return 2
    if script.problems:
        return _fail(script.problems, script.name, err)
    closes = [line for line in script.lines if isinstance(line.command, (Bye, Quit))]
    if closes and args.loop != 1:
        problem = script.problem(
            closes[0].number, "cannot --loop a file that closes the connection"
        )
        return _fail([problem], script.name, err)
    if args.check:
        print(f"{script.name}: {len(script.lines)} commands, all parse", file=out)
        return 0
    if not script.lines:
        print(f"{script.name}: no commands", file=out)
        return 0

    def notify(message: str) -> None:
        print(f"c2rviz-play: {message}", file=err, flush=True)

    client = Client(host, port, retry_s=args.timeout, notify=notify)
    show = Progress(out, err)
    errors = played = 0
    start = time.monotonic()
    try:
        names = client.joint_names()
        mismatch = robot_mismatch(script, client.robot or "?", names)
        if mismatch is not None and args.strict:
            return _fail([f"{mismatch} (--strict)"], script.name, err)
        if mismatch is not None:
            notify(f"warning: {mismatch}; playing it anyway (--strict refuses)")
        problems = check_robot(script, client.robot or "?", names)
        if problems:
            return _fail(problems, f"{script.name} (robot {client.robot})", err)
        loop = 0
        while args.loop == 0 or loop < args.loop:
            loop += 1
            prefix = f"{loop}: " if args.loop != 1 else ""
            errors += play(
                client,
                script,
                show,
                speed=args.speed,
                keep_going=args.keep_going,
                window=args.window,
                prefix=prefix,
            )
            played += 1
            if errors and not args.keep_going:
                break
    except ServerUnavailable as exc:
        notify(str(exc))
        return 1
    except ConnectionLost:
        return 1
    except C2rvizError as exc:
        notify(str(exc))
        return 1
    except KeyboardInterrupt:
        return 130
    finally:
        client.close()
    elapsed = time.monotonic() - start
    times = f"{played} x " if played != 1 else ""
    if errors:
        s = "" if errors == 1 else "s"
        print(f"{script.name}: {errors} error{s} ({times}{len(script.lines)} commands)", file=err)
        return 1
    print(
        f"{script.name}: {times}{len(script.lines)} commands, all ok, in {elapsed:.2f} s", file=out
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
