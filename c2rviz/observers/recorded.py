"""What a finished recording hands on, and what takes its frames as they are written."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from datetime import datetime
from pathlib import Path
from typing import Protocol

__all__ = ["FrameSink", "Recorded", "header"]


@dataclass(frozen=True)
class Recorded:
    """A finished recording (what an exporter needs to find and describe it).

    Attributes:
        name: Its name.
        robot: The robot model's name (the ``# robot:`` header).
        txt: The command file (None when a write error stopped it: see ``error``).
        csv: The frames.
        frames: Rows of the CSV.
        duration_s: Recorded time [s].
        started: When it began (UTC).
        sources: Who sent commands meanwhile.
        error: Why it stopped early, if it did.
        html: NAME.html, the run as a page that plays in any browser.
    """

    name: str
    robot: str
    txt: Path | None
    csv: Path
    frames: int
    duration_s: float
    started: datetime
    sources: tuple[str, ...]
    error: str | None = None
    html: Path | None = None
    """The self-contained page (``view.record_page``), once written."""
    bag: Path | None = None
    """The rosbag2 folder NAME/ (``bag_recorder``), once closed and in place."""


class FrameSink(Protocol):
    """Takes each frame a recorder writes (the bag)."""

    def frame(self, robot: str, t_s: float, at: float, q: Sequence[float]) -> None:
        """Robot ``robot`` was at ``q`` [rad or m] at ``t_s`` [s from the recording's
        start, as the CSV says], clock time ``at`` [s]."""


def header(
    name: str,
    robot: str,
    started: datetime,
    tally: tuple[float, int, float],
    sources: tuple[tuple[str, ...], int],
    early: str | None,
) -> str:
    """A command file's opening comments: recording ``name`` of the robot model ``robot``,
    begun at ``started``; ``tally``: its length [s], frames and most frames a second;
    ``sources``: who sent commands and how many more were not named; ``early``: why it
    stopped early, if it did (the player checks ``# robot:``)."""
    seconds, frames, hz = tally
    named, more = sources
    who = ", ".join(named) or "none"
    if more:
        who += f" and {more} more"
    stopped = "" if early is None else f"# stopped early: {early}\n"
    return (
        f"# c2rviz recording {name}: play it back with c2rviz-play {name}.txt\n"
        f"# robot: {robot}\n"
        f"# recorded: {started.isoformat(timespec='seconds')}, "
        f"{seconds:.3f} s, {frames} frames "
        f"(at most {hz:g} a second)\n"
        f"# sources: {who}\n"
        f"# frames: {name}.csv (time [s], joints [rad or m], tool pose x,y,z [m] "
        "roll,pitch,yaw [rad] in the base frame)\n"
        f"{stopped}"
    )
