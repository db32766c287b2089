"""A bag's span as command lines: what ``c2rviz-play BAG`` checks, sends or writes.

``BagSpan`` is the part of a bag's JointState topic that plays (``ros.bag_reader``'s
``JointStateBag``, from ``start_s`` for ``duration_s``, at ``rate`` times its pace)
for a chain of joints. ``check_span`` reads it whole and raises at the first thing a
player must not send; ``command_lines`` yields its ``joints`` lines with ``sleep``
lines between, read as they go; ``write_commands`` writes them as a command file.
No sockets here.
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from ..errors import within_limit

if TYPE_CHECKING:
    from ..ros.bag_reader import JointStateBag

__all__ = ["LONG_PAUSE_S", "BagSpan", "check_span", "command_lines", "open_bag", "write_commands"]

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
