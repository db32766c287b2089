"""The robots a program serves: one robot, or the members of a ``--cell``, each with what
the ini gives it (its tool, motion limits and workcell objects, ``ini_world``).

Reads only ``Settings`` (no flags object), so a test or another program builds the
same robots the command line would.

A work cell is several robots, each on its own command port, placed in one world: an ini
section ``[cell:NAME]`` whose ``robots`` key names member sections; each member says which
robot it is (any name ``--robot`` takes), where its base stands in the cell and which port
it listens on::

    [cell:twoarms]
    robots = left right
    [left]
    robot = motoman_sia20d
    origin = 0,0,0,0,0,0          # x,y,z [m], roll,pitch,yaw [deg] of its base
    port = 31000
    [right]
    robot = fanuc_lrmate200id
    origin = 1.2,0,0,0,0,180
    port = 31001

A member may instead be a robot section itself (``urdf = ...``, with ``base``,
``eelink`` and the other robot keys), plus its ``origin`` and ``port``.

``--cell NAME`` takes ``[cell:NAME]`` from the ini in use; ``--cell PATH`` reads
the ini file at PATH and takes its only cell. Every mistake is a ``ConfigError``
naming the section and the valid choices.
"""

from __future__ import annotations

import configparser
import math
from dataclasses import dataclass
from pathlib import Path

import pinocchio as pin

from ..collision.model import CollisionModel
from ..errors import C2rvizError, ConfigError
from ..ini import number, read_ini
from ..motion.limits import MotionLimits
from ..robot.catalogue import CatalogueEntry, find_robot
from ..robot.frames import pose_se3
from ..robot.model import Robot
from ..world.world import World
from .config import ROBOT_KEYS, Settings, read_robots
from .ini_world import (
    IniFault,
    IniObject,
    IniPart,
    gripper_from,
    ini_faults,
    ini_objects,
    ini_parts,
    limits_from,
    start_faults,
    tool_from,
)

_MEMBER_KEYS = ("robot", "origin", "port")


@dataclass(frozen=True)
class CellMember:
    """One robot of a cell.

    Attributes:
        name: Its name in the cell (the member section's name).
        entry: Which robot it is (URDF, chain ends).
        origin: x, y, z [m], roll, pitch, yaw [rad] of its base in the cell frame.
        port: Its command port as the ini fixes it (0 picks a free one; None: the base port
            plus its index).
        extras: Its robot section's ``tool`` and motion limits, as written (``furnish``).
        ini: The file the cell was read from.
    """

    name: str
    entry: CatalogueEntry
    origin: tuple[float, float, float, float, float, float]
    port: int | None
    extras: tuple[tuple[str, str], ...] = ()
    ini: Path | None = None


@dataclass(frozen=True)
class Cell:
    """A cell's name and its robots, in the order the ini lists them."""

    name: str
    members: tuple[CellMember, ...]


def load_cell(spec: str, ini: Path | None) -> Cell:
    """The cell ``spec`` names: ``[cell:spec]`` in ``ini``, or the only cell of the file ``spec``.

    Raises:
        ConfigError: no such cell, or a bad member (unknown robot, bad origin or port, a
            name or port used twice).
    """
    path = Path(spec)
    if path.suffix == ".ini" or path.is_file():
        if not path.is_file():
            raise ConfigError(f"cell file {spec!r} does not exist")
        ini, wanted = path, None
    elif ini is None:
        raise ConfigError(f"no cmdinterpreter.ini to find cell {spec!r} in (give --config)")
    else:
        wanted = spec
    parser = read_ini(ini)
    cells = [s.removeprefix("cell:") for s in parser.sections() if s.startswith("cell:")]
    if wanted is None:
        if len(cells) != 1:
            raise ConfigError(f"{ini} must hold exactly one [cell:NAME] section", cells)
        wanted = cells[0]
    if wanted not in cells:
        raise ConfigError(f"no [cell:{wanted}] in {ini}", cells)
    section = f"cell:{wanted}"
    names = parser.get(section, "robots", fallback="").split()
    if not names:
        raise ConfigError(f"[{section}] of {ini} needs robots = NAME NAME ...")
    robots = read_robots(ini)
    members = [_cell_member(parser, name, section, ini, robots) for name in names]
    for attribute in ("name", "port"):
        seen: dict[object, str] = {}
        for member in members:
            value = getattr(member, attribute)
            if attribute == "port" and value in (0, None):
                continue
            if value in seen:
                raise ConfigError(
                    f"[{section}] of {ini} uses {attribute} {value} twice "
                    f"({seen[value]} and {member.name}); give each robot its own"
                )
            seen[value] = member.name
    return Cell(wanted, tuple(members))


def _cell_member(
    parser: configparser.ConfigParser,
    name: str,
    cell: str,
    ini: Path,
    robots: dict,
) -> CellMember:
    if not parser.has_section(name):
        raise ConfigError(f"[{cell}] of {ini} names robot {name!r}, which has no [{name}] section")
    items = dict(parser.items(name))
    if "robot" not in items and "urdf" in items:  # the member is a robot section itself
        entry = find_robot(name, robots, ini)
    else:
        unknown = sorted(set(items) - set(_MEMBER_KEYS))
        if unknown:
            raise ConfigError(
                f"unknown key {unknown[0]!r} in [{name}] of {ini}", [*_MEMBER_KEYS, *ROBOT_KEYS]
            )
        if "robot" not in items:
            raise ConfigError(
                f"[{name}] of {ini} needs robot = NAME (any name --robot takes) or urdf = PATH"
            )
        entry = find_robot(items["robot"], robots, ini)
    given = items.get("port")
    port = None if given is None else number(f"[{name}] port", given, int, 0, 65535)
    extras = robots[entry.name].extras if entry.name in robots else ()
    origin = _origin(items.get("origin", "0,0,0,0,0,0"), name)
    return CellMember(name, entry, origin, port, extras, ini)


def _origin(text: str, name: str) -> tuple[float, float, float, float, float, float]:
    parts = [p.strip() for p in text.split(",")]
    try:
        values = [float(p) for p in parts]
    except ValueError:
        values = []
    if len(values) != 6 or not all(map(math.isfinite, values)):
        raise ConfigError(
            f"[{name}] origin = {text!r} must be 6 numbers: x,y,z (m),roll,pitch,yaw (deg)"
        )
    x, y, z, roll, pitch, yaw = values
    return (x, y, z, math.radians(roll), math.radians(pitch), math.radians(yaw))


@dataclass(frozen=True)
class Member:
    """One robot the program serves: its name, model, place in the world and port, and
    what the ini gives it (``ini_world``)."""

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
