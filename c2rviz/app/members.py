"""The robots a program serves: one robot, or the members of a ``--cell``, each with what
the ini gives it (its tool, motion limits and workcell objects, ``robot_options``).

Reads only ``Settings`` (no flags object), so a test or another program builds the
same robots the command line would.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import pinocchio as pin

from ..collision.model import CollisionModel
from ..errors import C2rvizError, ConfigError
from ..motion.limits import MotionLimits
from ..robot.frames import pose_se3
from ..robot.model import Robot
from ..world.world import World
from .cell import load_cell
from .config import Settings
from .ini_world import IniFault, IniPart, ini_faults, ini_parts, start_faults
from .robot_options import IniObject, gripper_from, ini_objects, limits_from, tool_from

__all__ = ["Member", "furnish", "members"]


@dataclass(frozen=True)
class Member:
    """One robot the program serves: its name, model, place in the world and port, and
    what the ini gives it (``robot_options``)."""

    name: str
    robot: Robot
    origin: pin.SE3
    port: int
    limits: MotionLimits
    tool: pin.SE3 | None = None
    objects: tuple[IniObject, ...] = ()
    faults: tuple[IniFault, ...] = ()
    parts: tuple[IniPart, ...] = ()


def members(settings: Settings) -> tuple[list[Member], str | None]:
    """The robots to serve and the cell's name: the cell's (``settings.cell``), or the one
    robot of the settings (no cell).

    Raises:
        C2rvizError: a robot, its ini extras or the cell cannot be read.
    """
    flags = dict(settings.motion_flags)
    if settings.cell is not None:
        cell = load_cell(settings.cell, settings.ini)
        found: list[Member] = []
        for index, part in enumerate(cell.members):
            found_robot = part.entry
            robot = Robot.from_urdf(
                found_robot.urdf,
                found_robot.base,
                found_robot.eelink,
                package_paths=found_robot.package_paths,
                xacro_args=found_robot.xacro_args,
            )
            given = {**dict(part.extras), **flags}
            found.append(
                _member(
                    part.name,
                    robot,
                    pose_se3(part.origin),
                    _cell_port(settings, part.port, index),
                    found_robot.name,
                    given,
                    part.ini,
                    not found,
                )
            )
        return found, cell.name
    assert settings.urdf is not None
    robot = Robot.from_urdf(
        settings.urdf,
        settings.base,
        settings.eelink,
        package_paths=settings.package_paths,
        xacro_args=settings.xacro_args,
    )
    # The name the user chose; a --urdf without --robot is named by its model.
    named_by_model = settings.urdf_flag and not settings.robot_flag
    name = robot.name if named_by_model else settings.robot
    entry = settings.robots.get(settings.robot)
    extras = entry.extras if entry is not None and not settings.urdf_flag else ()
    given = {**dict(extras), **flags}
    member = _member(
        name, robot, pin.SE3.Identity(), settings.port, name, given, settings.ini, True
    )
    return [member], None


def _cell_port(settings: Settings, fixed: int | None, index: int) -> int:
    """A cell member's command port: the base port plus its index, unless the ini fixes it
    and no ``--port`` was given (a flag wins over the ini); port 0 picks free ones."""
    if fixed is not None and not settings.port_flag:
        return fixed
    return settings.port + index if settings.port else 0


def furnish(world: World, member: Member) -> None:
    """Give a robot of the world its ini tool and objects (a bad object raises)."""
    if member.tool is not None:
        world.set_tool(member.name, member.tool)
    for name, shape, size, placement, rgba, mesh in member.objects:

        def add(model: CollisionModel) -> None:
            model.set_object(name, shape, size, placement, rgba, mesh)  # noqa: B023 (run now)

        world.edit_objects(member.name, add)
    start_faults(world, member.name, member.faults)
    base = world.state(member.name).base
    for name, shape, size, placement, kind, rgba in member.parts:
        try:
            world.parts.add(name, shape, size, base * placement, kind, rgba)
        except C2rvizError as exc:
            raise ConfigError(f"[parts] {name}: {exc}") from None


def _member(
    name: str,
    robot: Robot,
    origin: pin.SE3,
    port: int,
    section: str,
    given: dict[str, str],
    ini: Path | None,
    first: bool,
) -> Member:
    objects = tuple(ini_objects(ini, name, first)) if ini is not None else ()
    parts = tuple(ini_parts(ini, name, first)) if ini is not None else ()
    robot.gripper = gripper_from(section, given, robot)
    return Member(
        name,
        robot,
        origin,
        port,
        limits_from(section, given, robot),
        tool_from(section, given),
        objects,
        tuple(ini_faults(ini, name, robot, first)) if ini is not None else (),
        parts,
    )
