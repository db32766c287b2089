"""``c2rviz-play``: check a command file with the server's own parser, then play it.

The whole file is parsed with ``c2rviz.protocol.parse_line`` before anything is
sent, so a typo on line 40 is reported as ``file:40: error: ...`` (every such
line, up to ``script.MAX_PROBLEMS``) while the robot is still where it was; then the
file is read again line by line as it plays, so a long recording costs no more
memory than a short one. FILE is found as given, else in the recording folder, else
in the project's ``commands/`` (``connection.find_script``). Once connected, the joint
counts of ``joints`` lines and the indices of ``move`` lines are checked against the
server's robot (``names``), again before the first line is sent; a file that declares
its robot in its opening comments (a ``# robot: NAME`` line) and finds another
one at the server is warned about, or refused with ``--strict``. Then every command
line is sent and its reply shown; the first ``error:`` reply stops the play
(unless ``--keep-going``). The reading and checking is ``script``'s; this
module plays.

``sleep S`` lines are sent to the server as ``sleep S/speed``: the server
holds that connection's later lines until the pause is over and then replies
``ok``, so timing stays right even when lines are pipelined. Moves with
``motion on`` (from ``--motion on`` or the file's own line) are answered on
arrival, and the lines behind them wait the same way; on a terminal the
progress line says ``-> moving`` meanwhile.

Exit status: 0 every line got ``ok``; 1 a line got an error, or the server
could not be reached or went away; 2 the file or the options are wrong, or
the server refused ``--motion`` (nothing was sent); 130 interrupted.
"""

from __future__ import annotations

import argparse
import sys
import time
from collections import deque
from collections.abc import Sequence
from pathlib import Path
from typing import TextIO

from ..errors import C2rvizError
from ..protocol.verbs.arm import MOTION_MODES, MotionMode
from ..protocol.verbs.seed import Sleep
from .bag_play import add_bag_args, is_bag
from .bag_play import run as play_bag
from .client import Client
from .connection import ServerUnavailable, add_connection_args, find_script, server_address
from .errors import ConnectionLost
from .goto import motion_of
from .script import (
    Script,
    ScriptLine,
    check_robot,
    load_script,
    motion_after,
    robot_mismatch,
    waits_for_the_arm,
)
from .stream import Progress, shown


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
    motion: str | None = None,
) -> int:
    """Send every line of ``script`` (read from its file as it goes) and show its reply;
    return how many got an error.

    Args:
        client: An open or openable connection with no unread replies.
        script: A checked script with no ``problems``.
        show: Where lines, replies and errors go.
        speed: Sleeps are divided by this.
        keep_going: Go on after an ``error:`` reply.
        window: Lines sent ahead of their replies (1: wait for each reply).
            After an error, lines already sent have run; their replies are shown.
        prefix: Put before each ``k/n`` label (the loop number).
        motion: The connection's motion mode as the play starts (None: unknown,
            taken as ``off``); the file's own ``motion`` lines change it. While a
            line waits for the arm, ``show`` says so (``-> moving``).

    Raises:
        ConnectionLost: the server went away (already reported through ``show``).
        KeyboardInterrupt: Ctrl-C (reported through ``show``).
        C2rvizError: the file changed since it was checked (reported through ``show``).
    """
    n = script.count
    width = len(str(n))
    done = errors = 0
    mode = motion or "off"
    ahead: deque[ScriptLine] = deque()  # sent, reply not read yet
    lines = script.stream()
    sending = True
    last = 0  # the line number a stop is reported at
    try:
        while True:
            while sending and len(ahead) < window:
                next_line = next(lines, None)
                if next_line is None:
                    sending = False
                    break
                client.post(_wire(next_line, speed))
                ahead.append(next_line)
                last = next_line.number
            if not ahead:
                break
            line = ahead[0]
            last = line.number
            label = f"[{prefix}{done + 1:>{width}}/{n}]"
            if waits_for_the_arm(line.command, mode):
                show.waiting(label, line.wire, "moving")
            reply = client.read_reply()
            ahead.popleft()
            done += 1
            show.step(label, line.wire, reply)
            if isinstance(line.command, MotionMode) and line.command.mode and reply == "ok":
                mode = line.command.mode
            if not reply.startswith("ok"):
                errors += 1
                show.error(f"{script.name}:{line.number}: {reply}")
                if not keep_going:
                    sending = False  # what is already sent has run: show its replies
    except ConnectionLost as exc:
        show.error(script.problem(last, exc))
        raise
    except KeyboardInterrupt:
        show.error(f"{script.name}:{last}: interrupted")
        raise
    except C2rvizError as exc:
        show.error(str(exc))
        raise
    finally:
        lines.close()
    show.end_line()
    return errors


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="c2rviz-play",
        description="Check a c2rviz command file with the server's parser, then play it: "
        "each line is sent, its reply shown; the first error stops the play.",
        epilog="Exit status: 0 all lines ok; 1 a line got an error or no server; "
        "2 the file or an option does not check, or the server refused --motion "
        "(nothing was sent). FILE is looked for here, then in the recording folder, "
        "then in the project's commands/. A '# robot: NAME' line in the file's "
        "opening comments names the robot it is for.",
    )
    add = parser.add_argument
    add(
        "file",
        metavar="FILE",
        help="command file, e.g. commands/motoman.txt, or a ROS bag: a rosbag2 folder, an "
        ".mcap or .db3 file, or a ROS 1 .bag, whose JointState topic is played",
    )
    add_connection_args(parser)
    parser._option_string_actions["--port"].help = (  # argparse has no public setter
        "command port (default from cmdinterpreter.ini: 31000); for a CRCL program "
        "(FILE.xml), the CRCL port (default 64444)"
    )
    add(
        "--speed",
        "--rate",
        type=_positive,
        default=1.0,
        metavar="X",
        help="divide every sleep by X (default 1): X times the file's or the bag's pace",
    )
    add(
        "--motion",
        choices=MOTION_MODES,
        help="send 'motion off|on|follow' before the first line: with 'on' each move's "
        "reply comes when the arm arrives (default: the server's mode)",
    )
    add("--loop", type=int, default=1, metavar="N", help="play N times; 0: until Ctrl-C")
    add("--keep-going", action="store_true", help="go on after an error reply")
    add("--check", action="store_true", help="only parse the file; do not connect")
    add(
        "--quiet",
        "-q",
        action="store_true",
        help="print errors, warnings and the summary line only, not each line and its reply",
    )
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
    add_bag_args(parser)
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
    if args.file.lower().endswith(".xml"):  # a CRCLProgram: over the CRCL port
        from . import crcl_program  # the CRCL codec (lxml, numpy): loaded only for one

        return crcl_program.main(argv)
    out, err = sys.stdout, sys.stderr
    if is_bag(args.file):
        return play_bag(args, out, err)
    if args.loop < 0 or args.window < 1:
        print("c2rviz-play: --loop must be >= 0 and --window >= 1", file=err)
        return 2
    try:
        path = find_script(args.file, args.config)
        script = load_script(path, args.file)
        host, port = server_address(args.host, args.port, args.config)
    except (OSError, C2rvizError) as exc:
        print(f"c2rviz-play: {exc}", file=err)
        return 2
    if script.problems:
        return _fail(script.all_problems(), script.name, err)
    if path != Path(args.file) and not args.quiet:
        print(f"c2rviz-play: playing {path}", file=err, flush=True)
    if script.closes is not None and args.loop != 1:
        problem = script.problem(
            script.closes[0], "cannot --loop a file that closes the connection"
        )
        return _fail([problem], script.name, err)
    if args.check:
        print(f"{script.name}: {script.count} commands, all parse", file=out)
        return 0
    if not script.count:
        print(f"{script.name}: no commands", file=out)
        return 0

    def notify(message: str) -> None:
        print(f"c2rviz-play: {shown(message)}", file=err, flush=True)

    client = Client(host, port, retry_s=args.timeout, notify=notify)
    show = Progress(out, err, quiet=args.quiet)
    errors = played = 0
    start = time.monotonic()
    try:
        names = client.joint_names()
        mismatch = robot_mismatch(script, client.robot_name or "?", names)
        if mismatch is not None and args.strict:
            return _fail([f"{mismatch} (--strict)"], script.name, err)
        if mismatch is not None:
            notify(f"warning: {mismatch}; playing it anyway (--strict refuses)")
        problems = check_robot(script, client.robot_name or "?", names)
        if problems:
            return _fail(problems, f"{script.name} (robot {client.robot_name})", err)
        motion = args.motion
        if motion is not None:
            reply = client.ask(f"motion {motion}")
            if not reply.startswith("ok"):  # a server from before motion
                return _fail([f"--motion {motion}: the server replied {reply!r}"], script.name, err)
        elif show.in_place and not args.quiet:
            motion = motion_of(client.ask("motion"))  # to show "-> moving"; None: no motion
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
                motion=motion,
            )
            motion = motion_after(script, motion)
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
        print(f"{script.name}: {errors} error{s} ({times}{script.count} commands)", file=err)
        return 1
    print(f"{script.name}: {times}{script.count} commands, all ok, in {elapsed:.2f} s", file=out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
