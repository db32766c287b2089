"""``c2rviz-play BAG``: a ROS bag's joint states driving the robot, as timed ``joints`` lines.

A bag is a rosbag2 folder (with ``metadata.yaml``), a bare ``.mcap`` or ``.db3``
file, or a ROS 1 ``.bag``; ``ros.bag_reader.JointStateBag`` reads its
``sensor_msgs/JointState`` topic (``--topic``; the only one by default) through
the bag's index, streamed: memory stays flat however long the bag. Playing:

1. The chain is the server's (``names``; its ``limits`` bound every value), or
   ``--joints`` names it (then nothing is asked of a server).
2. The whole span that will play (``--start`` for ``--duration`` seconds of the
   bag's log time, to its end by default) is read and checked BEFORE the first
   line is sent: each message names every chain joint (a missing one is an error
   naming it; joints the chain does not have are listed once and ignored), every
   value is finite and within its limits, header stamps never go back. A bad
   value anywhere in the span moves nothing.
3. Then the span streams: ``radians`` and ``motion off`` (or ``--motion``), then a
   ``joints`` line per message (chain order, exact values) with ``sleep DT`` lines
   between them at the bag's pace divided by ``--rate`` (one line however long the
   gap; over ``LONG_PAUSE_S`` a warning); ``--window`` lines are sent ahead of their
   replies.
   ``--loop N`` plays the span N times (0: until Ctrl-C). The first ``error:``
   reply stops the play.

``--to-commands OUT`` writes the same lines into a command file instead (under a
private name, renamed when whole), which ``c2rviz-play OUT`` plays. The REPL's
``file BAG`` plays a bag the same way (``play_in_repl``).

The span as command lines comes first, with no sockets: ``BagSpan`` is the part of a bag's
JointState topic that plays (from ``start_s`` for ``duration_s``, at ``rate`` times its
pace) for a chain of joints; ``check_span`` reads it whole and raises at the first thing a
player must not send; ``command_lines`` yields its ``joints`` lines with ``sleep`` lines
between, read as they go; ``write_commands`` writes them as a command file. Then what
finds the chain and plays.

Exit status: 0 every line got ``ok``; 1 the bag or its span cannot be played (one
line saying why, nothing sent), a line got an error, or the server could not be
reached or went away; 2 the options are wrong; 130 interrupted.
"""

from __future__ import annotations

import argparse
import contextlib
import itertools
import os
import time
from collections import deque
from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, TextIO

from ..errors import C2rvizError, within_limit
from .client import Client
from .connection import ServerUnavailable, server_address
from .errors import ConnectionLost

if TYPE_CHECKING:
    from ..ros.bag_reader import JointStateBag


LONG_PAUSE_S = 3600.0
"""A pause longer than this (the server's default longest ``sleep``) is warned about."""


@dataclass(frozen=True)
class BagSpan:
    """What of a bag plays: its topic's span from ``start_s`` for ``duration_s``."""

    bag: JointStateBag
    chain: tuple[str, ...]
    start_s: float = 0.0
    duration_s: float | None = None
    rate: float = 1.0

    def samples(self, warnings: list[str] | None = None) -> Iterator[tuple[float, tuple]]:
        return self.bag.samples(self.chain, self.start_s, self.duration_s, warnings)


def check_span(span: BagSpan, limits: Sequence[tuple[float, float, str]] | None) -> list[str]:
    """Read the whole span and raise at the first thing that must not be sent; return the
    warnings (joints ignored, messages skipped), each once.

    Args:
        span: The span.
        limits: (lower, upper, unit) of each chain joint [rad or m], or None unknown.

    Raises:
        BagError: the first problem (one line).
    """
    from ..ros.errors import BadSample

    warnings: list[str] = []
    longest, at_s, previous_s = 0.0, 0.0, None
    for t_s, values in span.samples(warnings):
        if previous_s is not None and (t_s - previous_s) / span.rate > longest:
            longest, at_s = (t_s - previous_s) / span.rate, previous_s
        previous_s = t_s
        for k, (value, (lower, upper, unit)) in enumerate(zip(values, limits or ())):
            if not within_limit(value, lower, upper):
                raise BadSample(
                    str(span.bag.path),
                    f"joint {span.chain[k]!r} is {value:.10g} {unit} at {t_s:.6f} s, outside "
                    f"its limits {lower:g}..{upper:g} {unit} (the server's 'limits')",
                )
    if longest > LONG_PAUSE_S:
        warnings.append(
            f"a pause of {longest:.6g} s from {at_s:.6f} s: a server refuses a sleep over "
            f"its longest ({LONG_PAUSE_S:g} s unless --max-sleep); cut it with --start/--duration"
        )
    return warnings


def _seconds(us: float) -> str:
    return f"{us / 1e6:.6f}".rstrip("0").rstrip(".")


def command_lines(span: BagSpan) -> Iterator[str]:
    """``joints`` lines of the span, with one ``sleep`` line between two (read as they go):
    a line per message, however long the pause."""
    previous_us: int | None = None
    for t_s, values in span.samples():
        now_us = round(t_s * 1e6)
        if previous_us is not None:
            gap_us = (now_us - previous_us) / span.rate
            if gap_us > 0.5:  # under half a microsecond is no pause at all
                yield f"sleep {_seconds(gap_us)}"
        previous_us = now_us
        yield "joints " + ",".join([repr(float(v)) for v in values])


def open_bag(path: Path, topic: str | None) -> JointStateBag:
    """Open the bag at ``path`` and choose its JointState topic (rosbags loads only now).

    Raises:
        BagError: not a bag, damaged, or no such JointState topic (one line).
    """
    from ..ros.bag_reader import JointStateBag

    return JointStateBag.open(path, topic)


def write_commands(span: BagSpan, out: Path, robot: str | None, rate_note: str) -> int:
    """Write the span's lines to the command file ``out``; return the ``joints`` lines.

    Raises:
        OSError: ``out`` cannot be written (nothing is left half-written).
        BagError: the bag went bad while read.
    """
    private = out.with_name(f".{out.name}.{os.getpid()}.part")
    count = 0
    try:
        with open(private, "x", encoding="ascii") as file:
            file.write(
                f"# c2rviz commands from the bag {span.bag.path}: {span.bag.topic}, "
                f"from {span.start_s:g} s{rate_note}\n"
            )
            if robot is not None:
                file.write(f"# robot: {robot}\n")
            file.write("radians\nmotion off\n")
            for line in command_lines(span):
                file.write(line + "\n")
                count += line.startswith("joints")
        os.replace(private, out)
    except BaseException:
        with contextlib.suppress(OSError):
            private.unlink()
        raise
    return count


BAG_SUFFIXES = (".mcap", ".db3", ".bag")


def is_bag(name: str | Path) -> bool:
    """Whether ``name`` is meant as a bag: a folder, or a file ending in a bag's suffix."""
    path = Path(name)
    return path.is_dir() or path.suffix.lower() in BAG_SUFFIXES


def add_bag_args(parser: argparse.ArgumentParser) -> None:
    """The flags that apply when FILE is a bag."""
    group = parser.add_argument_group(
        "when FILE is a ROS bag (docs/recording.md)",
        "its JointState topic is checked over the whole span first, then played as timed "
        "joints lines ('motion off' unless --motion); a bag that cannot be played: exit 1, "
        "nothing sent",
    )
    add = group.add_argument
    add("--topic", metavar="NAME", help="the JointState topic (default: the only one)")
    add("--start", type=float, default=0.0, metavar="S", help="from S s into the bag (0)")
    add("--duration", type=float, metavar="S", help="play S s of it (default: to its end)")
    add(
        "--to-commands",
        metavar="OUT",
        type=Path,
        help="write the lines to the command file OUT instead of sending them",
    )
    add(
        "--joints",
        metavar="NAME,...",
        help="the chain's joint names, in order (default: ask the server with 'names')",
    )


def stream(client: Client, lines: Iterable[str], window: int, err: TextIO, name: str) -> int:
    """Send ``lines`` (``window`` ahead of their replies); stop at the first error reply.
    Return how many lines got an error (0 or 1).

    Raises:
        ConnectionLost: the server went away.
    """
    sent: deque[str] = deque()

    def settle() -> bool:
        line = sent.popleft()
        reply = client.read_reply()
        if reply.startswith("ok"):
            return True
        print(f"{name}: {line[:60]}: {reply}", file=err, flush=True)
        return False

    for line in lines:
        client.post(line)
        sent.append(line)
        if len(sent) >= window and not settle():
            while sent:  # what was sent ahead has run: read its replies
                settle()
            return 1
    while sent:
        if not settle():
            while sent:
                settle()
            return 1
    return 0


def _plan(args: argparse.Namespace, client: Client | None) -> tuple[BagSpan, list[str], str | None]:
    """Open the bag, find the chain, check the span (raises C2rvizError with one line)."""
    bag = open_bag(Path(args.file), args.topic)
    try:
        robot = None
        limits = None
        if args.joints is not None:
            chain = tuple(name.strip() for name in args.joints.split(",") if name.strip())
        else:
            assert client is not None
            chain = client.joint_names()
            robot = client.robot_name
            limits = client.limits()
        span = BagSpan(bag, chain, args.start, args.duration, args.speed)
        warnings = check_span(span, limits)
    except BaseException:
        bag.close()
        raise
    return span, warnings, robot


def run(args: argparse.Namespace, out: TextIO, err: TextIO) -> int:
    """``c2rviz-play BAG``'s main, after the flags are parsed; returns the exit status."""
    name = str(args.file)
    if args.loop < 0 or args.window < 1:
        print("c2rviz-play: --loop must be >= 0 and --window >= 1", file=err)
        return 2
    if args.to_commands is not None and args.loop != 1:
        print("c2rviz-play: --to-commands writes the span once; drop --loop", file=err)
        return 2
    client: Client | None = None
    if args.joints is None:
        try:
            host, port = server_address(args.host, args.port, args.config)
        except C2rvizError as exc:
            print(f"c2rviz-play: {exc}", file=err)
            return 2
        client = Client(host, port, retry_s=args.timeout, notify=lambda m: print(m, file=err))
    try:
        try:
            span, warnings, robot = _plan(args, client)
        except (ServerUnavailable, ConnectionLost) as exc:
            print(f"c2rviz-play: {exc}", file=err)
            return 1
        except C2rvizError as exc:
            print(f"c2rviz-play: {exc}; nothing was sent", file=err, flush=True)
            return 1
        with contextlib.closing(span.bag):
            for warning in warnings:
                print(f"c2rviz-play: warning: {name}: {warning}", file=err, flush=True)
            return _go(args, span, client, robot, out, err)
    except KeyboardInterrupt:
        print(f"{name}: interrupted", file=err)
        return 130
    finally:
        if client is not None:
            client.close()


def _go(
    args: argparse.Namespace,
    span: BagSpan,
    client: Client | None,
    robot: str | None,
    out: TextIO,
    err: TextIO,
) -> int:
    name = str(args.file)
    rate_note = "" if span.rate == 1 else f", at {span.rate:g} x its pace"
    if args.check:
        print(f"{name}: {span.bag.topic} plays (checked from {span.start_s:g} s)", file=out)
        return 0
    if args.to_commands is not None:
        try:
            count = write_commands(span, args.to_commands, robot, rate_note)
        except (OSError, C2rvizError) as exc:
            print(f"c2rviz-play: {args.to_commands}: {exc}", file=err)
            return 1
        print(f"{name}: {count} joints lines written to {args.to_commands}", file=out)
        return 0
    assert client is not None
    start = time.monotonic()
    loops = 0
    try:
        setup = ["radians", f"motion {args.motion or 'off'}"]
        while args.loop == 0 or loops < args.loop:
            if stream(client, itertools.chain(setup, command_lines(span)), args.window, err, name):
                return 1
            loops += 1
            setup = []
    except (ServerUnavailable, ConnectionLost) as exc:
        print(f"c2rviz-play: {exc}", file=err)
        return 1
    except C2rvizError as exc:  # the bag went bad after its check (changed on disk)
        print(f"c2rviz-play: {exc}", file=err)
        return 1
    times = f"{loops} x " if loops != 1 else ""
    print(
        f"{name}: {times}{span.bag.topic}{rate_note}, all ok, in {time.monotonic() - start:.2f} s",
        file=out,
    )
    return 0


def play_in_repl(client: Client, path: str, rate: float, out: TextIO) -> int:
    """The REPL's ``file BAG``: check and play the whole bag on ``client``; return 1 if
    anything went wrong (said on ``out``), else 0."""
    args = argparse.Namespace(
        file=path, topic=None, start=0.0, duration=None, joints=None, speed=rate
    )
    try:
        span, warnings, _ = _plan(args, client)
    except C2rvizError as exc:
        print(f"{exc}; nothing was sent", file=out, flush=True)
        return 1
    degrees, motion = client.in_degrees, client.motion()
    with contextlib.closing(span.bag):
        for warning in warnings:
            print(f"warning: {path}: {warning}", file=out, flush=True)
        setup = ["radians", "motion off"]
        errors = stream(client, itertools.chain(setup, command_lines(span)), 2, out, path)
    restore = ["degrees"] * degrees + ([f"motion {motion}"] if motion not in (None, "off") else [])
    errors += stream(client, restore, 1, out, path)  # the connection as it was
    if not errors:
        print(f"{path}: {span.bag.topic}, all ok", file=out, flush=True)
    return min(errors, 1)
