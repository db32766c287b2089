"""The errors of ``record``: each one line that says what was wrong and what to do."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from ..errors import C2rvizError

__all__ = [
    "AlreadyRecording",
    "LinkedName",
    "NotABagFolder",
    "NameInUse",
    "NotRecording",
    "NotYourRecording",
    "RecordFolderError",
    "RecordingError",
    "RecordingExists",
]


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
