"""What a recording shows the rest of the program: what a finished one hands on, what
takes its frames as they are written, and the errors of ``record`` (each one line that
says what was wrong and what to do).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from datetime import datetime
from pathlib import Path
from typing import Protocol

from ..errors import C2rvizError


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


class RecordingError(C2rvizError):
    """A ``record`` command that cannot be done."""


class RecordingExists(RecordingError):
    """A file of NAME is already in the folder (and ``overwrite`` was not said)."""

    def __init__(self, name: str, folder: Path) -> None:
        self.name = name
        self.folder = folder
        super().__init__(
            f"record: {name} already exists in {folder}; choose another name or say "
            f"'record {name} overwrite'"
        )


class AlreadyRecording(RecordingError):
    """The robot is being recorded already (one recording per robot at a time)."""

    def __init__(self, name: str, seconds: float, robot: str | None = None) -> None:
        self.name = name
        self.seconds = seconds
        self.robot = robot
        if robot is None:
            message = f"record: {name} is being recorded ({seconds:.1f} s); 'record stop' first"
        else:
            message = (
                f"record: robot {robot} is being recorded as {name} ({seconds:.1f} s); "
                "'record stop' from its connection first"
            )
        super().__init__(message)


class NameInUse(RecordingError):
    """Another robot's recording runs under the same name."""

    def __init__(self, name: str, robots: Sequence[str]) -> None:
        self.name = name
        self.robots = tuple(robots)
        super().__init__(
            f"record: {name} is being recorded (robot {', '.join(self.robots)}); "
            "choose another name"
        )


class NotRecording(RecordingError):
    """``record stop`` with no recording running."""

    def __init__(self) -> None:
        super().__init__("record: nothing is being recorded")


class NotYourRecording(RecordingError):
    """``record stop`` from a connection whose robot is not recorded, while another is."""

    def __init__(self, robot: str, running: Sequence[tuple[str, str]]) -> None:
        self.robot = robot
        self.running = tuple(running)
        others = ", ".join(f"{name} (robot {who})" for name, who in self.running)
        super().__init__(
            f"record: robot {robot} is not being recorded; {others} can be stopped only "
            "from a connection driving its robot ('robot NAME' chooses)"
        )


class RecordFolderError(RecordingError):
    """The recording folder cannot be made or written."""

    def __init__(self, folder: Path, why: str) -> None:
        self.folder = folder
        self.why = why
        super().__init__(f"record: cannot record into {folder}: {why}")


class LinkedName(RecordingError):
    """A file (or the bag folder) of the name is a symbolic link: never written through."""

    def __init__(self, path: Path) -> None:
        self.path = path
        super().__init__(
            f"record: {path} is a symbolic link, and recordings never write through links; "
            "remove it or choose another name"
        )


class NotABagFolder(RecordingError):
    """NAME/ is a folder holding more than a recording's bag: never replaced."""

    def __init__(self, path: Path) -> None:
        self.path = path
        super().__init__(
            f"record: {path} is a folder that is not a recording's bag, and 'overwrite' "
            "replaces only recordings; move it or choose another name"
        )
