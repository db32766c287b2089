"""Recording: what happens to one robot, from every source, kept in two files.

A ``Recorder`` is an observer of the world (so it sees the TCP clients, the page
and replays alike) that writes, in the recording folder:

- ``NAME.txt``, a command file ``c2rviz-play NAME.txt`` plays back to the same
  states at the same times: ``radians``, ``motion off``, then ``joints``,
  ``mark`` (after ``color`` and ``marker`` when they change), ``clear`` and
  ``sleep S`` between them. Its opening ``#`` comments name the robot
  (``# robot: NAME``, which the player checks), when it was recorded and the
  sources that sent commands.
- ``NAME.csv``, one row per frame: ``time`` [s from the start], each joint by name
  [rad or m], and the tool pose ``x,y,z`` [m] ``roll,pitch,yaw`` [rad] in the base
  frame (as ``pose`` gives it), with a header row; values to 10 significant digits
  as replies give them (NAME.txt keeps them exact, so a replay is the same states).

It never slows the command path: states are coalesced to at most one frame per
``1/hz`` of the world's clock (a state superseded within a frame is dropped; the
latest is written at the frame's time, when it was what the arm showed), and
files are written through large buffers, flushed once a second. Each frame also
goes to a ``FrameSink`` if one is given (the bag, ``bag_recorder``), with the
CSV's time. A write error (a full disk) stops the recording with one warning and
an ``event record-stopped`` to watchers; the server goes on, and what was written
is kept (each file cut after its last whole line). The files are written under
private names (``record_files``) and put in place when the recording is
finished; the command file's header needs the sources, known only at the end,
so its body is written apart and ``finish`` puts the two together.
"""

from __future__ import annotations

import contextlib
import logging
import os
from collections.abc import Callable, Sequence
from datetime import datetime, timezone
from pathlib import Path
from typing import TextIO

import numpy as np

from ..collision.workcell import WorkcellObject
from ..protocol import replies
from ..robot.frames import in_base, se3_pose, wxyz_se3
from ..world.cameras import Camera
from ..world.observer import Observer
from ..world.parts import Part
from ..world.state import Marker
from ..world.world import World
from .camera_feed import CameraSignature, camera_changes, camera_signature
from .record_files import RecordFiles, body_tally, cut_to_line, join_body
from .recorded import (
    FaultLines,
    FrameSink,
    PartSignature,
    Recorded,
    csv_columns,
    csv_poses,
    exact,
    header,
    object_lines,
    opening_lines,
    part_changes,
    signature,
    workcell_lines,
)

log = logging.getLogger("c2rviz.recorder")

BUFFER_BYTES = 1 << 18
"""Write buffer of each file [bytes]."""
FLUSH_S = 1.0
"""Files are flushed at most this often [s of the world's clock] (and at the end)."""
_MAX_SOURCES = 100  # sources named in the header; the rest are counted


class Recorder(Observer):
    """One recording of one robot of a world (the world's clock times it)."""

    def __init__(
        self,
        world: World,
        robot: str,
        name: str,
        folder: Path | RecordFiles,
        on_failed: Callable[[Recorder, str], None],
        *,
        t0: float | None = None,
        bag: FrameSink | None = None,
    ) -> None:
        """Open the files and write the state now (the caller checked the name and folder).

        Args:
            world: What is recorded.
            robot: The robot's name in the world.
            name: The recording's name (files NAME.txt and NAME.csv).
            folder: An existing folder, or the recording's ``RecordFiles`` in one.
            on_failed: Called once, on the asyncio thread, when a write error stops it.
            t0: The clock time [s] its times count from (default: now).
            bag: Where each frame also goes.

        Raises:
            OSError: a file cannot be created.
        """
        self.world = world
        self.robot = robot
        self.name = name
        self.files = folder if isinstance(folder, RecordFiles) else RecordFiles(folder, name)
        self.state = world.state(robot)
        self.period_s = world.frame_s
        self.on_failed = on_failed
        self.bag = bag
        self.started = datetime.now(timezone.utc)
        self.t0 = world.clock.now() if t0 is None else t0
        self.txt = self.files.private(".txt")  # put together by `finish`
        self.csv = self.files.private(".csv")
        self.part = self.files.private(".txt.part")
        self.sources: dict[str, None] = {}
        self.more_sources = 0
        self.frames = 0
        self.error: str | None = None
        """Why its own files stopped early (a write error), if they did."""
        self.early: str | None = None
        """Why the recording stopped early, if it did (its own error, or its bag's)."""
        self.closed = False
        self._due = -np.inf  # when the next frame may be written [clock s]
        self._pending: Sequence[float] | None = None  # the latest state, not yet written
        self._written_us = 0  # time of the last line of the command file [us from t0]
        self._flushed = self.t0
        self._faults = FaultLines()  # lines waiting for the arm to rest, the last slip outcome
        self._rgb = (1.0, 0.0, 0.0)  # a replaying session's marker style
        self._shape = "sphere"
        self._body: TextIO = self.files.open_text(".txt.part", BUFFER_BYTES)
        try:
            self._rows: TextIO = self.files.open_text(".csv", BUFFER_BYTES)
        except OSError:
            self._body.close()
            self.files.discard(".txt.part")
            raise
        joints = ",".join(self.state.robot.joint_names)
        self._csv_parts = world.parts.parts.names()  # each one's pose in every row
        columns = "".join(csv_columns(name) for name in self._csv_parts)
        self._write(self._rows, f"time,{joints},x,y,z,roll,pitch,yaw{columns}\n")
        self._write(self._body, "radians\nmotion off\nclear\n")
        for marker in self.state.markers:
            self._mark(marker)
        self._write(self._body, workcell_lines(world, robot))
        self._parts: PartSignature = signature(world.parts.parts.all())
        self._cameras: CameraSignature = {}
        self.on_cameras(world.cameras.all())
        self._frame(self.state.q, self.t0)
        names = self.state.robot.joint_names
        on = opening_lines(world.faults.of(robot), world.cameras.all(), self.t0, names)
        self._write(self._body, "".join(f"{line}\n" for line in on))  # the faults on now

    @property
    def seconds(self) -> float:
        """How long it has been recording [s]."""
        return self.world.clock.now() - self.t0

    # The world's effects.

    def on_joints(self, robot: str, q: Sequence[float], t: float) -> None:
        if robot != self.robot or self.closed:
            return
        if t < self._due:  # the hot path: a flood of commands within one frame
            self._pending = q
        else:
            self.flush_due(t)
            if t >= self._due:
                self._frame(q, t)
            else:
                self._pending = q
        if self._faults.waiting and not self.world.moving(robot):  # a stop's braking ended
            self._write_faults()

    def on_marker(self, robot: str, marker: Marker) -> None:
        if robot == self.robot and not self.closed:
            self._catch_up(self.world.clock.now())
            self._mark(marker)

    def on_clear_markers(self, robot: str) -> None:
        if robot == self.robot and not self.closed:
            self._catch_up(self.world.clock.now())
            # `clear` also homes the arm: put it back at once where it is (the home move,
            # if this clear came with one, follows as frames).
            self._write(self._body, f"clear\njoints {exact(self.state.q)}\n")

    def on_fault(self, robot: str, text: str) -> None:
        """A fault's line goes after the frames it caused: at once, or (a protective stop
        braking) once the arm rests, so a replay never refuses its own frames; a drop at
        once, mid-move too, so the replay drops the part where the run did."""
        mine = robot == self.robot and not self.closed
        if mine and self._faults.add(text, self.world.moving(robot)):
            self._write_faults()

    def on_part_event(self, robot: str | None, text: str) -> None:
        """A grasp that drew for a slip: its outcome goes before its ``grip`` line, so the
        replay makes the same grasp (recorded.py)."""
        if robot == self.robot and not self.closed:
            line = self._faults.outcome(self.world.faults.of(robot), text)
            if line is not None:
                self._arm_now(self.world.clock.now())
                self._write(self._body, f"{line}\n")

    def _write_faults(self) -> None:
        now = self.world.clock.now()
        if self._pending is not None:  # the arm as the fault found it comes first
            pending, self._pending = self._pending, None
            self._frame(pending, now)
        self._sleep_to(now)
        self._write(self._body, "".join(f"{line}\n" for line in self._faults.take()))

    def on_objects(self, robot: str, objects: Sequence[WorkcellObject]) -> None:
        if robot == self.robot and not self.closed:
            self._catch_up(self.world.clock.now())
            self._write(self._body, object_lines(objects))

    def on_parts(self, parts: Sequence[Part], t: float) -> None:
        if self.closed:
            return
        if signature(parts) != self._parts:
            self._catch_up(t)
            self._write(self._body, part_changes(self._parts, parts, self.state.base))
            self._parts = signature(parts)
        if self._csv_parts:  # a part moved (falling, carried): a frame, as if the arm did
            self.on_joints(self.robot, self.state.q, t)

    def on_cameras(self, cameras: Sequence[Camera]) -> None:
        """The cameras as commands, whenever they change (camera_feed)."""
        if not self.closed and camera_signature(cameras) != self._cameras:
            self._catch_up(self.world.clock.now())
            self._write(self._body, camera_changes(self._cameras, cameras))
            self._cameras = camera_signature(cameras)

    def on_gripper(self, robot: str, opening: float, t: float) -> None:
        if robot == self.robot and not self.closed:
            self._arm_now(t)
            self._write(self._body, f"grip {opening!r}\n")

    def _arm_now(self, t: float) -> None:
        """The arm as it is at ``t`` (its pending state), for a line whose rule needs the
        joints of now (the grasp rule)."""
        self._catch_up(t)
        if self._pending is not None:
            pending, self._pending = self._pending, None
            self._frame(pending, t)

    def on_command(self, source: str, line: str, accepted: bool) -> None:
        if accepted and source not in self.sources:
            if len(self.sources) < _MAX_SOURCES:
                self.sources[source] = None
            else:
                self.more_sources += 1

    # Writing.

    def flush_due(self, t: float) -> None:
        """Write the pending state if its frame came at or before clock time ``t`` [s]."""
        if self._pending is not None and t >= self._due and not self.closed:
            pending, self._pending = self._pending, None
            self._frame(pending, self._due)  # it was still the arm's state then

    def _catch_up(self, t: float) -> None:
        """Write the pending state if its frame came before ``t``; then the time to ``t``."""
        self.flush_due(t)
        self._sleep_to(t)

    def _sleep_to(self, t: float) -> int:
        us = round((t - self.t0) * 1e6)
        if us > self._written_us:
            seconds = f"{(us - self._written_us) / 1e6:.6f}".rstrip("0").rstrip(".")
            self._write(self._body, f"sleep {seconds}\n")
            self._written_us = us
        return us

    def _frame(self, q: Sequence[float], t: float) -> None:
        us = self._sleep_to(t)
        self._due = t + self.period_s
        pose = replies.numbers(se3_pose(self.state.robot.ee_pose(q) * self.state.tool))
        self._write(self._body, f"joints {exact(q)}\n")  # exact: a replay is the same
        poses = csv_poses(self.world.parts.parts, self._csv_parts, self.state.base)
        self._write(self._rows, f"{us / 1e6:.6f},{replies.numbers(q)},{pose}{poses}\n")
        self.frames += 1
        if self.bag is not None:
            self.bag.frame(self.robot, us / 1e6, t, q)
        if t - self._flushed >= FLUSH_S and not self.closed:
            self._flushed = t
            try:
                self._body.flush()
                self._rows.flush()
            except OSError as exc:
                self._fail(exc)

    def _mark(self, marker: Marker) -> None:
        lines = []
        if marker.rgb != self._rgb:
            self._rgb = marker.rgb
            lines.append(f"color {exact(marker.rgb)}\n")
        if marker.shape != self._shape:
            self._shape = marker.shape
            lines.append(f"marker {marker.shape}\n")
        pose = se3_pose(in_base(self.state.base, wxyz_se3(marker.position, marker.wxyz)))
        lines.append(f"mark {exact(pose)}\n")
        self._write(self._body, "".join(lines))

    def _write(self, file: TextIO, text: str) -> None:
        if self.closed:
            return
        try:
            file.write(text)
        except OSError as exc:
            self._fail(exc)

    def _fail(self, exc: OSError) -> None:
        """A write failed: stop here, keep what is on disk, tell the desk."""
        self.error = f"write error: {exc.strerror or exc}"
        log.warning(
            "recording %s stopped by a %s; what was written up to it is kept", self.name, self.error
        )
        self._close_files()
        self.on_failed(self, self.error)

    def _close_files(self) -> None:
        self.closed = True
        for file in (self._body, self._rows):
            with contextlib.suppress(OSError, ValueError):
                file.close()

    # The end.

    def stop(self) -> None:
        """Write the last state and close the files (on the asyncio thread)."""
        if self.closed:
            return
        now = self.world.clock.now()
        if self._pending is not None:
            pending, self._pending = self._pending, None
            self._frame(pending, min(now, self._due))
        self._sleep_to(now)
        if self.closed:
            return
        self.closed = True
        try:
            self._body.close()
            self._rows.close()
        except OSError as exc:
            self._fail(exc)

    def finish(self) -> Recorded:
        """Put the command file together under its private name (blocking: for a thread).

        The header, then the body up to its last whole line. Should that not be
        written (a full disk), the body alone becomes the command file (it plays, with
        no header). After a write error the CSV is cut after its last whole row too, and
        the frames and time the header and ``Recorded`` give are those the body kept (the
        frames still in a buffer when the disk filled never reached it).
        """
        txt: Path | None = None
        if self.error is not None:
            with contextlib.suppress(OSError, ValueError):
                cut_to_line(self.part)
                self.frames, self._written_us = body_tally(self.part)
        try:
            self._assemble()
            txt = self.txt
        except OSError as exc:
            self.error = self.error or f"write error: {exc.strerror or exc}"
            self.files.discard(".txt")
            with contextlib.suppress(OSError):
                cut_to_line(self.part)
                os.replace(self.part, self.txt)
                txt = self.txt
        if self.error is not None:
            with contextlib.suppress(OSError):
                cut_to_line(self.csv)
        return Recorded(
            self.name,
            self.state.robot.name,
            txt,
            self.csv,
            self.frames,
            self._written_us / 1e6,
            self.started,
            tuple(self.sources),
            self.error,
        )

    def _assemble(self) -> None:
        join_body(self.files.create(".txt"), self.header(), self.part, BUFFER_BYTES)
        self.part.unlink()

    def header(self) -> str:
        """NAME.txt's opening comments (``recorded.header``)."""
        tally = (self._written_us / 1e6, self.frames, 1 / self.period_s)
        sources = (tuple(self.sources), self.more_sources)
        why = self.error or self.early
        return header(self.name, self.state.robot.name, self.started, tally, sources, why)
