"""The recordings of a world: where they go, the ones running (one per robot), and their end.

Each robot has its own recording (``start(name, robot)``): NAME.txt and
NAME.csv (``Recorder``) and the bag NAME/ (``BagRecorder``), from every source.
``start(name, robot, every=True)`` records every robot of the world at once, as
one recording: per robot NAME.ROBOT.txt and NAME.ROBOT.csv (NAME.txt and
NAME.csv when the world has one robot), and one bag NAME/ holding every robot's
topics. A recording is stopped for one of its robots (``stop``), which stops it
whole; the session refuses a ``record stop`` for a robot not recorded.

Stopping returns a future that is done when the files are complete and in place: in a
thread (``finish``) the bag is ended, each command file put together, each exporter the
app gave (the page NAME.html) run, and every file renamed from its private name
(``record_files``) to its own. Two recordings of the same name finish one after the other,
in the order they stopped, so ``record NAME overwrite`` racing a ``record stop`` of NAME
loses neither: each is complete when its ``record stop`` is answered, and the later one
holds the names. A name whose files are symbolic links is refused. ``close`` stops every
recording and waits for every one still finishing (the program's exit).
"""

from __future__ import annotations

import asyncio
import logging
import os
import re
import shutil
from collections.abc import Callable, Coroutine, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..errors import C2rvizError
from ..world.observer import Observer
from ..world.state import RobotState
from ..world.world import World
from .record_files import RecordFiles, existing, is_bag_folder, links
from .recorded import (
    AlreadyRecording,
    LinkedName,
    NameInUse,
    NotABagFolder,
    NotRecording,
    NotYourRecording,
    Recorded,
    RecordFolderError,
    RecordingExists,
)
from .recorder import Recorder

if TYPE_CHECKING:
    from .bag_recorder import BagRecorder


log = logging.getLogger("c2rviz.record")


DEFAULT_FOLDER = Path("recordings")
"""Where recordings go unless told (``--record-dir``, ini ``record_dir``)."""

_FILE_PART = re.compile(r"[^A-Za-z0-9_.-]")


class Recordings:
    """The recordings of one world: the folder, the running ones, the last one finished."""

    def __init__(
        self,
        world: World,
        folder: Path = DEFAULT_FOLDER,
        tell: Callable[[str], None] | None = None,
        exporters: Sequence[Exporter] = (),
        bag: bool = True,
    ) -> None:
        """Set up.

        Args:
            world: What is recorded.
            folder: Where recordings go (made when needed).
            tell: Tells every watcher an event (``record-stopped NAME: WHY``).
            exporters: What else is written from a finished recording (in order).
            bag: Write the bag NAME/ too.
        """
        self.world = world
        self.folder = folder
        self.tell = tell
        self.exporters = tuple(exporters)
        self.bag = bag
        self.running: dict[str, Recording] = {}
        """The recording of each robot being recorded."""
        self.last: Recorded | None = None
        self._finishing: dict[str, asyncio.Future[list[Recorded]]] = {}  # by stem
        self._in_flight: set[asyncio.Future[list[Recorded]]] = set()

    def recorder(self, robot: str | None = None) -> Recorder | None:
        """The recorder of ``robot`` (the world's default robot for None), if recorded."""
        name = self.world.default if robot is None else robot
        recording = self.running.get(name)
        return None if recording is None else recording.recorders[name]

    @property
    def current(self) -> Recorder | None:
        """The default robot's recorder (a world of one robot has only that one)."""
        return self.recorder()

    # Starting.

    def start(
        self, name: str, robot: str, overwrite: bool = False, every: bool = False
    ) -> Recording:
        """Begin recording ``robot`` (``every``: every robot of the world) as ``name``.

        Raises:
            AlreadyRecording, NameInUse, RecordingExists, LinkedName, RecordFolderError.
        """
        robots = list(self.world.robots) if every else [robot]
        for each in robots:
            if each in self.running:
                now = self.running[each]
                seconds = self.world.clock.now() - now.t0
                raise AlreadyRecording(now.name, seconds, None if each == robot else each)
        several = len(robots) > 1
        stems = {r: f"{name}.{_FILE_PART.sub('_', r)}" if several else name for r in robots}
        self._check_names(name, set(stems.values()) | {name}, overwrite)
        t0 = self.world.clock.now()
        bag_files = RecordFiles(self.folder, name)
        recording = Recording(name, {}, None, bag_files, t0)
        try:
            if self.bag:
                from .bag_recorder import BagRecorder

                recording.bag = BagRecorder(
                    self.world, robots, bag_files.bag_folder(), t0, self._bag_failed
                )
            for each in robots:
                recorder = Recorder(
                    self.world,
                    each,
                    stems[each],
                    RecordFiles(self.folder, stems[each]),
                    self._failed,
                    t0=t0,
                    bag=recording.bag,
                )
                recording.recorders[each] = recorder
                if recording.bag is not None:
                    recording.bag.peers.append(recorder)
        except (OSError, C2rvizError) as exc:
            self._abandon(recording)
            why = exc.strerror or str(exc) if isinstance(exc, OSError) else str(exc)
            raise RecordFolderError(self.folder, why) from None
        observers: list[Observer] = [*recording.recorders.values()]
        if recording.bag is not None:
            observers.append(recording.bag)
        self.world.add_observers(observers)
        for each in robots:
            self.running[each] = recording
        return recording

    def _check_names(self, name: str, stems: set[str], overwrite: bool) -> None:
        folder = self.folder
        try:
            folder.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise RecordFolderError(folder, exc.strerror or str(exc)) from None
        for other in {id(r): r for r in self.running.values()}.values():
            if other.stems & stems:
                raise NameInUse(name, list(other.recorders))
        for stem in sorted(stems):
            linked = links(folder, stem)
            if linked:
                raise LinkedName(linked[0])
        bag = folder / name
        if bag.is_dir() and not is_bag_folder(bag, name):
            raise NotABagFolder(bag)
        if not overwrite and any(
            existing(folder, stem) or stem in self._finishing for stem in stems
        ):
            raise RecordingExists(name, folder)

    def _abandon(self, recording: Recording) -> None:
        """A start that failed half-way: close and remove what it made."""
        for recorder in recording.recorders.values():
            recorder.stop()
            recorder.files.discard(".txt.part", ".csv")
        if recording.bag is not None:
            recording.bag.close()
        parent = recording.bag_files.bag_parent
        if parent.is_dir() and not parent.is_symlink():
            shutil.rmtree(parent, ignore_errors=True)

    # Stopping.

    def stop(self, robot: str, why: str) -> asyncio.Future[list[Recorded]]:
        """End the recording of ``robot`` (``why``: who stopped it) and every robot's in it;
        the files are complete and in place when the returned future is done.

        Raises:
            NotRecording: nothing is being recorded.
            NotYourRecording: ``robot`` is not, but another robot is.
        """
        recording = self.running.get(robot)
        if recording is None:
            others = {id(r): r for r in self.running.values()}.values()
            if not others:
                raise NotRecording()
            raise NotYourRecording(robot, [(r.name, ", ".join(r.recorders)) for r in others])
        return self._end(recording, why)

    def _end(self, recording: Recording, why: str) -> asyncio.Future[list[Recorded]]:
        """Detach ``recording``, write its last frames, and finish it in a thread."""
        if not any(self.running.get(r) is recording for r in recording.recorders):
            done: asyncio.Future[list[Recorded]] = asyncio.get_running_loop().create_future()
            done.set_result([])  # ended already (a write error and a stop at once)
            return done
        for robot in recording.recorders:
            del self.running[robot]
        parts = [*recording.recorders.values(), recording.bag]
        for part in parts:
            if part is not None and part in self.world.observers:
                self.world.remove_observer(part)
        for recorder in recording.recorders.values():
            recorder.stop()
        if recording.bag is not None:
            recording.bag.stop()
        if self.tell is not None:
            self.tell(f"record-stopped {recording.name}: {why}")
        before = {self._finishing[s] for s in recording.stems if s in self._finishing}
        states = {r: self.world.state(r) for r in recording.recorders}
        future = asyncio.ensure_future(self._finish_after(before, recording, states))
        for stem in recording.stems:
            self._finishing[stem] = future
        self._in_flight.add(future)
        future.add_done_callback(lambda done: self._finished(recording, done))
        return future

    async def _finish_after(
        self,
        before: set[asyncio.Future[list[Recorded]]],
        recording: Recording,
        states: dict[str, RobotState],
    ) -> list[Recorded]:
        if before:  # the same name, stopped earlier: put in place first
            await asyncio.wait(before)
        return await asyncio.to_thread(finish, recording, states, self.exporters)

    def _finished(self, recording: Recording, future: asyncio.Future[list[Recorded]]) -> None:
        self._in_flight.discard(future)
        for stem in recording.stems:
            if self._finishing.get(stem) is future:
                del self._finishing[stem]
        if not future.cancelled() and future.exception() is None and future.result():
            self.last = future.result()[-1]
        elif not future.cancelled() and future.exception() is not None:
            log.error("recording %s: finishing failed", recording.name, exc_info=future.exception())

    def _failed(self, recorder: Recorder, error: str) -> None:
        self._failing(lambda r: recorder in r.recorders.values(), error)

    def _bag_failed(self, bag: BagRecorder, error: str) -> None:
        self._failing(lambda r: r.bag is bag, error)

    def _failing(self, match: Callable[[Recording], bool], error: str) -> None:
        # Called from inside the world's fan-out: leave its list of observers alone now.
        for recording in {id(r): r for r in self.running.values()}.values():
            if match(recording):
                for recorder in recording.recorders.values():
                    recorder.early = recorder.early or error
                asyncio.get_running_loop().call_soon(self._end, recording, error)
                return

    def close(self, why: str) -> Coroutine[Any, Any, list[Recorded]]:
        """Stop every recording now; return a coroutine that waits for every one to be
        finished, those stopped earlier too (the program's end), and gives what was
        finished, in the order they stopped."""
        ending = list(self._in_flight)  # stopped earlier, still being finished
        for recording in list({id(r): r for r in self.running.values()}.values()):
            ending.append(self._end(recording, why))
        return self._all_finished(ending)

    async def _all_finished(self, ending: list[asyncio.Future[list[Recorded]]]) -> list[Recorded]:
        """What ``ending`` (and any finish started meanwhile) gave, in the order they stopped;
        a finish already done when this is awaited counts too."""
        finished: list[Recorded] = []
        awaited: set[asyncio.Future[list[Recorded]]] = set()
        while waiting := [
            f for f in dict.fromkeys((*ending, *self._in_flight)) if f not in awaited
        ]:
            awaited.update(waiting)
            for result in await asyncio.gather(*waiting, return_exceptions=True):
                if isinstance(result, list):
                    finished.extend(result)
        return finished


Exporter = Callable[[Recorded, RobotState], Path]
"""Writes one more file from a finished recording (blocking, run in a thread) next to its
CSV and returns its path, such as ``view.record_page.write_html``'s NAME.html."""


@dataclass(eq=False)
class Recording:
    """One running recording: its name, a recorder per robot, and the bag."""

    name: str
    recorders: dict[str, Recorder]
    bag: BagRecorder | None
    bag_files: RecordFiles
    t0: float

    @property
    def stems(self) -> set[str]:
        """The names its files take (NAME, and NAME.ROBOT for each robot of a cell's)."""
        return {self.name, *(r.name for r in self.recorders.values())}


def finish(
    recording: Recording, states: dict[str, RobotState], exporters: Sequence[Exporter]
) -> list[Recorded]:
    """End the bag, put each command file together, run the exporters, and put every file
    in place (blocking: for a thread). What cannot be written is reported in ``error``."""
    bag: Path | None = None
    bag_error: str | None = None
    if recording.bag is not None:
        try:
            bag_error = recording.bag.close()
            bag = recording.bag_files.publish_bag()
        except Exception as exc:  # the txt and csv stand whatever the bag does
            bag_error = bag_error or f"the bag: {exc}"
            log.warning("recording %s: the bag is not in place: %s", recording.name, exc)
    out = []
    for robot, recorder in recording.recorders.items():
        recorded = recorder.finish()
        files = recorder.files
        html = None
        for export in exporters:
            try:
                _fresh(files, ".html")
                html = export(recorded, states[robot])
            except Exception as exc:  # the txt and csv stand; the rest is a bonus
                files.discard(".html")
                why = exc.strerror or exc if isinstance(exc, OSError) else exc
                log.warning(
                    "recording %s: no page written (%s.html): %s; its other files stand",
                    recorded.name,
                    recorded.name,
                    why,
                )
        try:
            txt = files.publish(recorded.txt) if recorded.txt is not None else None
            csv = files.publish(recorded.csv)
            if html is not None and html.name.startswith(files.stem):
                html = files.publish(html)
        except OSError as exc:
            why = f"cannot put it in place: {exc.strerror or exc}"
            log.warning("recording %s: %s (its files are %s.*)", recorded.name, why, files.stem)
            out.append(replace(recorded, error=recorded.error or why, bag=bag))
            continue
        error = recorded.error or (f"bag {bag_error}" if bag_error else None)
        out.append(replace(recorded, txt=txt, csv=csv, html=html, bag=bag, error=error))
    return out


def _fresh(files: RecordFiles, suffix: str) -> None:
    """Create the private file an exporter writes (so it opens a new file of ours, never a
    link someone put there)."""
    os.close(files.create(suffix))
