"""What a recording shows the rest of the program: what a finished one hands on, what
takes its frames as they are written, and the errors of ``record`` (each one line that
says what was wrong and what to do); and what its command file says besides commands:
its header, and the cell (the workcell, the parts and the faults), so that a replay
rebuilds it.

``Recorder`` writes, in the recorded robot's base frame and exact numbers: the objects
(``object all remove``, then one ``object`` line each; a mesh, which a client cannot
send, is a ``#`` comment) whenever they change, the parts at the start (``part all
remove``, then one ``part`` line each) and each part added or removed later, and every
opening of the gripper (``grip S``) so the replay grasps and releases by the same rule at
the same joints. A part held when the recording starts is written free where it is.

NAME.csv gets six more columns for each part there when the recording starts
(``NAME.x`` .. ``NAME.yaw``: its pose in the base frame [m, rad]; empty once removed).

Faults: ``Recorder`` writes each fault's line at its time (``fault_line``: the world's
``replay_line``), after the frames it caused. Two kinds of line are not a fault event's
own:

- **At the start**, the faults already on (``opening_lines``): each lasting fault's
  ``fault KIND ARGS`` (an estop cleared but not yet reset as ``fault estop`` then ``fault
  clear estop``, so the replay too waits for ``reset``) and each camera's blackout for
  the time it has left. The recorder writes them after the first frame, so a stalled
  joint holds where the arm is. Scheduled faults are not written ahead: each is written
  when it begins, as every fault is. ``latency`` and ``disconnect`` are never written
  (they would act on the replaying client itself).
- **Slips**: a replay must make the grasps the run made, not draw on chance again. So
  ``fault slip P`` is written as a comment, and before each grasp that drew
  (``slip_outcome``) ``fault slip 1`` (it slipped) or ``fault slip 0`` (it held), when
  it differs from the last one written: the replay's draws meet a certainty.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from datetime import datetime
from pathlib import Path
from typing import Protocol

import pinocchio as pin

from ..collision.workcell import WorkcellObject
from ..errors import C2rvizError
from ..protocol import replies
from ..robot.frames import se3_pose
from ..world.cameras import Camera
from ..world.faults import RobotFaults, at_once, replay_line
from ..world.parts import Part, Parts
from ..world.world import World


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


PartSignature = dict[str, tuple[object, ...]]
"""What identifies each part in a recording (name to shape, size, type, colour)."""


def exact(values: Sequence[float]) -> str:
    """Exact values (shortest round-trip form), comma-separated: a replay is the same."""
    return ",".join(repr(float(v)) for v in values)


def object_lines(objects: Sequence[WorkcellObject]) -> str:
    """The workcell as commands (placements in the base frame)."""
    lines = ["object all remove\n"]
    for obj in objects:
        if obj.shape == "mesh":
            lines.append(f"# object {obj.name}: a mesh from the ini ({obj.mesh_path})\n")
            continue
        lines.append(
            f"object {obj.name} {obj.shape} {exact(obj.size)} {exact(se3_pose(obj.placement))}\n"
        )
    return "".join(lines)


def part_line(part: Part, base: pin.SE3) -> str:
    """The command that adds ``part`` where it is, in the frame whose world pose is ``base``."""
    pose = exact(se3_pose(base.inverse() * part.pose))
    kind = f" type={part.kind}" if part.kind else ""
    colour = f" color={exact(part.obj.rgba[:3])}"
    return f"part {part.name} {part.obj.shape} {exact(part.obj.size)} {pose}{kind}{colour}\n"


def signature(parts: Sequence[Part]) -> PartSignature:
    return {p.name: (p.obj.shape, p.obj.size, p.kind, p.obj.rgba) for p in parts}


def part_changes(before: PartSignature, parts: Sequence[Part], base: pin.SE3) -> str:
    """The commands from the parts ``before`` to ``parts``: removals, then additions."""
    now = signature(parts)
    lines = [f"part {name} remove\n" for name in before if before[name] != now.get(name)]
    lines += [part_line(p, base) for p in parts if before.get(p.name) != now[p.name]]
    return "".join(lines)


def workcell_lines(world: World, robot: str) -> str:
    """The objects, the parts and the gripper of ``robot`` at a recording's start, when
    there are parts or objects (a recording of neither is as it was before parts)."""
    model = world.contacts.models.get(robot)
    objects = model.object_list() if model is not None else []
    parts = world.parts.parts.all()
    if not objects and not parts:
        return ""
    state = world.state(robot)
    lines = object_lines(objects) + "part all remove\n"
    lines += "".join(part_line(part, state.base) for part in parts)
    if state.robot.gripper is not None:
        lines += f"grip {state.opening!r}\n"
    return lines


def csv_columns(name: str) -> str:
    """The CSV header's columns for part ``name`` (each starting with a comma)."""
    return "".join(f",{name}.{axis}" for axis in ("x", "y", "z", "roll", "pitch", "yaw"))


def csv_poses(parts: Parts, names: Sequence[str], base: pin.SE3) -> str:
    """The CSV row's values for the parts ``names`` (each starting with a comma)."""
    cells = []
    inverse = base.inverse()
    for name in names:
        if name in parts:
            cells.append("," + replies.numbers(se3_pose(inverse * parts.get(name).pose)))
        else:
            cells.append(",,,,,,")
    return "".join(cells)


SLIPPED = "fault slip 1"
"""Written before a grasp that slipped: the replay's draw cannot hold."""
HELD = "fault slip 0"
"""Written before a grasp that held: the replay's draw cannot slip."""


def fault_line(text: str) -> str | None:
    """The line that replays the fault event ``text`` (None: none), ``fault slip P`` as a
    comment (each grasp's outcome is written instead)."""
    line = replay_line(text)
    if line is not None and line.startswith("fault slip "):
        return f"# {line} (each grasp's draw follows: {SLIPPED} slipped, {HELD} held)"
    return line


def slip_outcome(faults: RobotFaults, event: str) -> str | None:
    """The outcome line of the grasp a part event tells (``slipped NAME``: it slipped;
    ``grasped NAME`` with a slip fault on: it drew and held), None for any other event."""
    if event.startswith("slipped "):
        return SLIPPED
    if event.startswith("grasped ") and "slip" in faults.active:
        return HELD
    return None


def opening_lines(
    faults: RobotFaults, cameras: Sequence[Camera], now: float, joint_names: tuple[str, ...]
) -> list[str]:
    """The lines that put on, in a replay, the faults on at clock time ``now`` [s]: those of
    ``faults`` (a robot's) and the blackouts of ``cameras``."""
    lines = []
    for fault, _ in faults.active.values():
        line = fault_line(f"fault {fault.text(joint_names)}")
        if line is not None:
            lines.append(line)
    latch = faults.latch
    if latch is not None and latch.kind == "estop" and latch.released:
        lines += ["fault estop", "fault clear estop"]
    for camera in cameras:
        if camera.dark(now):
            left = camera.blackout_until - now
            timed = f" {left!r}" if math.isfinite(left) else ""
            lines.append(f"fault blackout {camera.name}{timed}")
    return lines


@dataclass
class FaultLines:
    """One recording's fault lines: those waiting for the arm to rest, and the last grasp
    outcome written (``slip``)."""

    waiting: list[str] = field(default_factory=list)
    slip: str | None = None

    def add(self, text: str, moving: bool) -> bool:
        """Keep the line of the fault event ``text``, if it has one; True: write the
        waiting lines now (the arm rests, or it is a line written at once: a drop)."""
        line = fault_line(text)
        if line is None:
            return False
        if "slip" in line:  # a slip begins or ends: the next grasp's outcome is written
            self.slip = None
        self.waiting.append(line)
        return not moving or (self.waiting == [line] and at_once(line))

    def take(self) -> list[str]:
        """The waiting lines, to write now."""
        lines, self.waiting = self.waiting, []
        return lines

    def outcome(self, faults: RobotFaults, event: str) -> str | None:
        """The outcome line to write before the grasp the part event ``event`` tells (None:
        no draw, or the same outcome as the last one written)."""
        line = slip_outcome(faults, event)
        if line is None or line == self.slip:
            return None
        self.slip = line
        return line
