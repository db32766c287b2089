"""The cell in a recording's command file: the workcell, the parts and the faults, so that a
replay rebuilds them.

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

import pinocchio as pin

from ..collision.workcell import WorkcellObject
from ..protocol import replies
from ..robot.frames import se3_pose
from ..world.cameras import Camera
from ..world.faults import RobotFaults, at_once, replay_line
from ..world.parts import Part, Parts
from ..world.world import World

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
