"""Every robot ``--robot NAME`` can name, and where each comes from.

Two places: the robot sections of cmdinterpreter.ini (they win on a name clash),
then the arms shipped by the ``example-robot-data`` package when it is installed
(``pip install example-robot-data``). Its releases from 5 on are data only,
installed under a ``cmeel.prefix/share`` folder in site-packages and found
through the package's installed-file list; older ones had a Python module that
names the folder. Each example robot comes with the base and end-effector links
of its arm, so ``c2rviz --robot ur5`` needs nothing else.
"""

from __future__ import annotations

import importlib
import importlib.metadata
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from typing import Protocol

from ..errors import ConfigError

# name -> (URDF under example-robot-data's robots/ folder, base link, end-effector link).
# The ends are the arm's: the flange or tool frame its maker or its SRDF names.
EXAMPLE_ROBOTS: dict[str, tuple[str, str, str]] = {
    "ur3": ("ur_description/urdf/ur3_robot.urdf", "base_link", "tool0"),
    "ur5": ("ur_description/urdf/ur5_robot.urdf", "base_link", "tool0"),
    "ur10": ("ur_description/urdf/ur10_robot.urdf", "base_link", "tool0"),
    "panda": ("panda_description/urdf/panda.urdf", "panda_link0", "panda_hand_tcp"),
    "kinova": (
        "kinova_description/robots/kinova.urdf",
        "j2s6s200_link_base",
        "j2s6s200_end_effector",
    ),
    "xarm7": ("xarm_description/urdf/xarm7.urdf", "link_base", "link_eef"),
    "z1": ("z1_description/urdf/z1.urdf", "link00", "link06"),
    "so100": ("so_arm_description/urdf/so100.urdf", "base", "gripper"),
    "so101": ("so_arm_description/urdf/so101.urdf", "base_link", "gripper_frame_link"),
    "baxter_left": ("baxter_description/urdf/baxter.urdf", "base", "left_gripper"),
    "baxter_right": ("baxter_description/urdf/baxter.urdf", "base", "right_gripper"),
    "double_pendulum": (
        "double_pendulum_description/urdf/double_pendulum.urdf",
        "base_link",
        "link2",
    ),
}


class _IniRobot(Protocol):
    """What a cmdinterpreter.ini robot section provides (``config.RobotEntry``)."""

    @property
    def urdf(self) -> Path: ...
    @property
    def base(self) -> str | None: ...
    @property
    def eelink(self) -> str | None: ...
    @property
    def package_paths(self) -> tuple[str | Path, ...]: ...
    @property
    def xacro_args(self) -> tuple[str, ...]: ...
    @property
    def ini(self) -> Path | None: ...


@dataclass(frozen=True)
class CatalogueEntry:
    """One robot ``--robot NAME`` can load.

    Attributes:
        name: What ``--robot`` takes.
        urdf: The URDF or xacro file.
        base: First link of the chain (None: the root).
        eelink: End-effector link (None: the only leaf).
        package_paths: Extra ``--package-path`` entries its meshes need (``DIR`` or
            ``NAME=DIR``).
        origin: Where it comes from, for ``--list-robots``.
        xacro_args: ``name:=value`` for a xacro file.
    """

    name: str
    urdf: Path
    base: str | None
    eelink: str | None
    package_paths: tuple[str | Path, ...]
    origin: str
    xacro_args: tuple[str, ...] = ()


@cache
def example_robot_data_dir() -> Path | None:
    """The installed ``example-robot-data`` package folder (holding ``robots/``), or None."""
    try:
        dist = importlib.metadata.distribution("example-robot-data")
    except importlib.metadata.PackageNotFoundError:
        dist = None
    if dist is not None:
        for file in dist.files or ():
            if file.parts[-2:] == ("example-robot-data", "package.xml"):
                folder = Path(str(dist.locate_file(file))).parent
                if (folder / "robots").is_dir():
                    return folder
    try:  # releases before 5 ship a Python module that names the folder
        module = importlib.import_module("example_robot_data.path")
    except ImportError:
        return None
    robots = Path(getattr(module, "EXAMPLE_ROBOT_DATA_MODEL_DIR", ""))
    return robots.parent if (robots / "ur_description").is_dir() else None


def _version() -> str:
    try:
        return importlib.metadata.version("example-robot-data")
    except importlib.metadata.PackageNotFoundError:
        return "?"


@cache
def example_robots() -> dict[str, CatalogueEntry]:
    """The example-robot-data arms that are installed, by name (empty without the package)."""
    folder = example_robot_data_dir()
    if folder is None:
        return {}
    origin = f"example-robot-data {_version()}"
    entries = {}
    for name, (relative, base, eelink) in EXAMPLE_ROBOTS.items():
        urdf = folder / "robots" / relative
        if urdf.is_file():
            # Its URDFs say package://example-robot-data/robots/...: the folder above.
            entries[name] = CatalogueEntry(name, urdf, base, eelink, (folder.parent,), origin)
    return entries


def catalogue(
    ini_robots: Mapping[str, _IniRobot] | None = None, ini: Path | None = None
) -> dict[str, CatalogueEntry]:
    """The ini's robots, then the installed example robots not named the same."""
    where = f"{ini}" if ini is not None else "cmdinterpreter.ini"
    ini_robots = ini_robots or {}
    entries = {
        name: CatalogueEntry(
            name, r.urdf, r.base, r.eelink, r.package_paths, str(r.ini or where), r.xacro_args
        )
        for name, r in ini_robots.items()
    }
    for name, entry in example_robots().items():
        entries.setdefault(name, entry)
    return entries


def find_robot(
    name: str, ini_robots: Mapping[str, _IniRobot] | None = None, ini: Path | None = None
) -> CatalogueEntry:
    """The robot called ``name``.

    Raises:
        ConfigError: no such robot, naming the ones there are.
    """
    entries = catalogue(ini_robots, ini)
    if name in entries:
        return entries[name]
    where = f"in {ini}" if ini is not None else "(no cmdinterpreter.ini found)"
    if example_robot_data_dir() is None:
        where += " or example-robot-data (not installed: pip install example-robot-data)"
    else:
        where += " or example-robot-data"
    own = sorted(ini_robots or {})  # the ini's robots first, then the example ones
    raise ConfigError(f"unknown robot {name!r} {where}", own + [n for n in entries if n not in own])


def listing(entries: Iterable[CatalogueEntry]) -> str:
    """The ``--list-robots`` text: one robot per line, then where others can be found."""
    rows = [
        (e.name, f"{e.base or '(root)'} -> {e.eelink or '(leaf)'}", e.origin, str(e.urdf))
        for e in entries
    ]
    widths = [max([len(h), *(len(r[i]) for r in rows)]) for i, h in enumerate(_HEADER)]
    lines = [
        "  ".join(c.ljust(w) for c, w in zip(row, widths)).rstrip() for row in [_HEADER, *rows]
    ]
    folder = example_robot_data_dir()
    if folder is None:
        lines.append("More arms: pip install example-robot-data (ur5, panda, ...).")
    else:
        lines.append(
            f"Other descriptions in {folder / 'robots'} load with --urdf PATH "
            "(and --base/--eelink where the robot branches)."
        )
    return "\n".join(lines)


_HEADER = ("robot", "chain", "from", "urdf")
