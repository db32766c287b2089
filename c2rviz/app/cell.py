"""A work cell: several robots, each on its own command port, placed in one world.

A cell is an ini section ``[cell:NAME]`` whose ``robots`` key names member
sections; each member says which robot it is (any name ``--robot`` takes),
where its base stands in the cell and which port it listens on::

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

from ..errors import ConfigError
from ..ini import read_ini
from ..robot.catalogue import CatalogueEntry, find_robot
from .config import ROBOT_KEYS, number, read_robots

__all__ = ["Cell", "CellMember", "load_cell"]

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
    members = [_member(parser, name, section, ini, robots) for name in names]
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


def _member(
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
