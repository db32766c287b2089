"""What a finished recording hands on, and what takes its frames as they are written."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from datetime import datetime
from pathlib import Path
from typing import Protocol

__all__ = ["FrameSink", "Recorded"]


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
