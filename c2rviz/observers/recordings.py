"""The recordings of a world: where they go, the one running, and the ``record`` errors.

One recording at a time per world (the app makes one ``Recordings`` and hands it
to the sessions); it records the robot of the source that started it, from every
source. Stopping returns a future that is done when the files are complete (the
command file is put together in a thread, then each exporter the app gave, such as
the page ``NAME.html``, writes its file from the finished recording).
"""

from __future__ import annotations

import asyncio
import logging
from collections.abc import Callable, Sequence
from dataclasses import replace
from pathlib import Path

from ..errors import C2rvizError
from ..world.state import RobotState
from ..world.world import World
from .recorder import Recorded, Recorder

log = logging.getLogger("c2rviz.record")

__all__ = [
    "DEFAULT_FOLDER",
    "AlreadyRecording",
    "NotRecording",
    "RecordFolderError",
    "RecordingError",
    "RecordingExists",
    "Exporter",
    "Recordings",
]

DEFAULT_FOLDER = Path("recordings")
"""Where recordings go unless told (``--record-dir``, ini ``record_dir``)."""

Exporter = Callable[[Recorded, RobotState], Path]
"""Writes one more file from a finished recording (blocking, run in a thread) and returns
its path, such as ``view.record_page.write_html``'s NAME.html."""


class RecordingError(C2rvizError):
    """A ``record`` command that cannot be done."""


class RecordingExists(RecordingError):
    """NAME.txt or NAME.csv is already in the folder (and ``overwrite`` was not said)."""

    def __init__(self, name: str, folder: Path) -> None:
        self.name = name
        self.folder = folder
        super().__init__(
            f"record: {name} already exists in {folder}; choose another name or say "
            f"'record {name} overwrite'"
        )


class AlreadyRecording(RecordingError):
    """A recording runs already (one at a time)."""

    def __init__(self, name: str, seconds: float) -> None:
        self.name = name
        self.seconds = seconds
        super().__init__(f"record: {name} is being recorded ({seconds:.1f} s); 'record stop' first")


class NotRecording(RecordingError):
    """``record stop`` with no recording running."""

    def __init__(self) -> None:
        super().__init__("record: nothing is being recorded")


class RecordFolderError(RecordingError):
    """The recording folder cannot be made or written."""

    def __init__(self, folder: Path, why: str) -> None:
        self.folder = folder
        self.why = why
        super().__init__(f"record: cannot record into {folder}: {why}")


class Recordings:
    """The recordings of one world: the folder, the one running, the last one finished."""

    def __init__(
        self,
        world: World,
        folder: Path = DEFAULT_FOLDER,
        tell: Callable[[str], None] | None = None,
        exporters: Sequence[Exporter] = (),
    ) -> None:
        """Set up.

        Args:
            world: What is recorded.
            folder: Where recordings go (made when needed).
            tell: Tells every watcher an event (``record-stopped NAME: WHY``).
            exporters: What else is written from a finished recording (in order).
        """
        self.world = world
        self.folder = folder
        self.tell = tell
        self.exporters = tuple(exporters)
        self.current: Recorder | None = None
        self.last: Recorded | None = None

    def start(self, name: str, robot: str, overwrite: bool = False) -> Recorder:
        """Begin recording ``robot`` as ``name``.

        Raises:
            AlreadyRecording, RecordingExists, RecordFolderError.
        """
        if self.current is not None:
            raise AlreadyRecording(self.current.name, self.current.seconds)
        folder = self.folder
        try:
            folder.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise RecordFolderError(folder, exc.strerror or str(exc)) from None
        if not overwrite and any(
            (folder / f"{name}{ext}").exists() for ext in (".txt", ".csv", ".html")
        ):
            raise RecordingExists(name, folder)
        try:
            recorder = Recorder(self.world, robot, name, folder, self._failed)
        except OSError as exc:
            raise RecordFolderError(folder, exc.strerror or str(exc)) from None
        self.world.add_observers([recorder])
        self.current = recorder
        return recorder

    def stop(self, why: str) -> asyncio.Future[Recorded]:
        """End the recording (``why``: who stopped it); the files are complete when the
        returned future is done.

        Raises:
            NotRecording: none runs.
        """
        recorder = self.current
        if recorder is None:
            raise NotRecording()
        self._detach(recorder, why)
        recorder.stop()
        future = asyncio.ensure_future(
            asyncio.to_thread(_finish, recorder, recorder.state, self.exporters)
        )
        future.add_done_callback(self._finished)
        return future

    def _finished(self, future: asyncio.Future[Recorded]) -> None:
        if not future.cancelled() and future.exception() is None:
            self.last = future.result()

    def _failed(self, recorder: Recorder, error: str) -> None:
        # Called from inside the world's fan-out: leave its list of observers alone now.
        asyncio.get_running_loop().call_soon(self._detach, recorder, error)
        self.last = recorder.finish()

    def _detach(self, recorder: Recorder, why: str) -> None:
        """The recording ends (once: a write error while closing says nothing more)."""
        if self.current is not recorder:
            return
        self.current = None
        if recorder in self.world.observers:
            self.world.remove_observer(recorder)
        if self.tell is not None:
            self.tell(f"record-stopped {recorder.name}: {why}")


def _finish(recorder: Recorder, state: RobotState, exporters: Sequence[Exporter]) -> Recorded:
    """NAME.txt put together, then each exporter's file (blocking: for a thread)."""
    recorded = recorder.finish()
    for export in exporters:
        try:
            recorded = replace(recorded, html=export(recorded, state))
        except Exception as exc:  # the txt and csv stand; the rest is a bonus
            log.warning("recording %s: no page written: %s", recorded.name, exc)
    return recorded
