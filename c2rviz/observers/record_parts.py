"""The workcell and the parts in a recording's command file, so that a replay rebuilds them.

``Recorder`` writes, in the recorded robot's base frame and exact numbers: the objects
(``object all remove``, then one ``object`` line each; a mesh, which a client cannot
send, is a ``#`` comment) whenever they change, the parts at the start (``part all
remove``, then one ``part`` line each) and each part added or removed later, and every
opening of the gripper (``grip S``) so the replay grasps and releases by the same rule at
the same joints. A part held when the recording starts is written free where it is.

NAME.csv gets six more columns for each part there when the recording starts
(``NAME.x`` .. ``NAME.yaw``: its pose in the base frame [m, rad]; empty once removed).
"""

from __future__ import annotations

from collections.abc import Sequence

import pinocchio as pin

from ..collision.workcell import WorkcellObject
from ..protocol import replies
from ..robot.frames import se3_pose
from ..world.parts import Part, Parts
from ..world.world import World

__all__ = [
    "PartSignature",
    "csv_columns",
    "csv_poses",
    "exact",
    "object_lines",
    "part_changes",
    "part_line",
    "signature",
    "workcell_lines",
]

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
