"""Settings: cmdinterpreter.ini, overridden by command-line flags.

The ini file has an ``[options]`` section and one section per robot (named as
in the seed: ``[motoman_sia20d]`` ...) with ``base``, ``eelink`` and ``urdf``
(relative to the ini file), and optionally ``package_path`` (where
``package://`` packages are: each entry ``DIR`` or ``NAME=DIR``, as for
``--package-path``, relative to the ini file) and ``xacro_args``
(``name:=value`` ...), each a space-separated list. A robot name with no section
is looked up in the catalogue (example-robot-data). Every bad value is a
``ConfigError`` naming the key and what it accepts.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from ..errors import ConfigError
from ..ini import INI_NAME, PROJECT_DIR, number, read_ini
from ..protocol.limits import bounds, default
from ..robot.catalogue import catalogue, find_robot
from ..robot.sources import split_package_path
from ..session.services import ServerLimits, SessionDefaults
from ..world.virtual_clock import parse_clock


@dataclass(frozen=True)
class RobotEntry:
    """One robot section of the ini file."""

    name: str
    urdf: Path
    base: str | None = None
    eelink: str | None = None
    package_paths: tuple[str | Path, ...] = ()
    """``package_path`` entries made absolute: a folder ``Path``, or ``"NAME=/abs/DIR"``."""
    xacro_args: tuple[str, ...] = ()
    ini: Path | None = None
    """The file the section was read from."""
    extras: tuple[tuple[str, str], ...] = ()
    """``tool``, ``gripper``, ``max_velocity``, ``max_acceleration``, ``max_jerk`` as written
    (see ``furnish``, which checks them)."""

    def check_package_paths(self) -> None:
        """Raise ConfigError, naming ``[section] package_path``, for an entry that is no folder."""
        for entry in self.package_paths:
            name, folder = split_package_path(entry)
            if not folder.is_dir():
                named = f" (for package {name})" if name is not None else ""
                raise ConfigError(
                    f"[{self.name}] package_path in {self.ini}: {str(folder)!r}{named} "
                    "is not a folder (entries are DIR or NAME=DIR, relative to the ini file)"
                )


def _package_paths(text: str, ini: Path) -> tuple[str | Path, ...]:
    """The ``package_path`` entries of a section, each made absolute against the ini's folder."""
    entries: list[str | Path] = []
    for entry in text.split():
        name, folder = split_package_path(entry, ini.parent)
        entries.append(folder if name is None else f"{name}={folder}")
    return tuple(entries)


@dataclass(frozen=True)
class Settings:
    """Everything the program needs to start."""

    host: str = "127.0.0.1"
    port: int = 31000
    hz: float = 100.0
    viewer_host: str = "127.0.0.1"
    viewer_port: int = 8080
    viewer_port_named: bool = False
    """The user chose ``viewer_port`` (``--viser-port`` or the ini): taken, it stops the
    program; the default taken, the page moves to the next free port."""
    viewer: bool = True
    viewer_origins: tuple[str, ...] = ()
    """Origins allowed to open the viewer's websocket besides its own (a reverse proxy)."""
    viewer_token: str | None = None
    """The token the page needs (``?token=``); None: none, unless bound beyond loopback."""
    max_viewers: int = default("page", "max_clients")
    """Viewer tabs connected at once."""
    viewer_lighting: str = "studio"
    """How the page lights its scene (``--viewer-lighting``, ini ``viewer_lighting``):
    ``studio`` (viser's environment map and shadows) or ``plain`` (lights only, for a
    computer without a GPU; ``view.adapter.LIGHTINGS``)."""
    page_process: bool = False
    """Serve the page from a process of its own (``--page-process``, ini ``page_process =
    on``; docs/page.md)."""
    rosbridge: bool = True
    """Serve rosbridge (``--no-rosbridge``: not)."""
    rosbridge_port: int | None = None
    """The rosbridge websocket's port (``--rosbridge-port``, ini ``rosbridge_port``); None:
    the default 9090, which costs only the door when taken."""
    robot: str = "motoman_sia20d"
    urdf: Path | None = None
    base: str | None = None
    eelink: str | None = None
    package_paths: tuple[str | Path, ...] = ()
    """``package://`` search folders (``DIR`` or ``NAME=DIR``), flags first."""
    xacro_args: tuple[str, ...] = ()
    """``name:=value`` for a ``.xacro`` robot, the robot section's then the flags'."""
    record_dir: Path = Path("recordings")
    """Where ``record NAME`` writes (the ini's is relative to the ini file)."""
    record: str | None = None
    """Record from start to exit under this name (``--record``)."""
    record_overwrite: bool = False
    """``--record NAME`` may replace an existing NAME (``--record-overwrite``)."""
    trail_points: int = 20_000
    """Points a ``trail`` keeps at most."""
    limits: ServerLimits = field(default_factory=ServerLimits)
    session: SessionDefaults = field(default_factory=SessionDefaults)
    robots: Mapping[str, RobotEntry] = field(default_factory=dict)
    ini: Path | None = None
    max_objects: int = 100
    """Most workcell objects per robot."""
    srdf: Path | None = None
    """An SRDF whose ``disable_collisions`` pairs are never checked."""
    cell: str | None = None
    """Serve the robots of this cell (``--cell``): an ini section's name, or an ini file."""
    motion_flags: tuple[tuple[str, str], ...] = ()
    """``--max-velocity`` and the like as given, (key, text), over every robot's ini ones."""
    clock: str = "real"
    """The world's clock (``--clock``): ``real``, ``scaled:N`` or ``virtual``
    (``world.clock.parse_clock``)."""
    robot_flag: bool = False
    """``--robot`` was given."""
    port_flag: bool = False
    """``--port`` was given (a cell's members then take it as their base port)."""
    urdf_flag: bool = False
    """``--urdf`` was given (the robot is then named by its model unless ``--robot`` is)."""
    crcl: bool = True
    """Open the CRCL door (``--no-crcl``: not)."""
    crcl_port: int | None = None
    """The CRCL port (``--crcl-port``, ini ``crcl_port``; a cell's robots take it and the
    next ones); None: the default, 64444, which another program may hold."""


# ini key -> (Settings or ServerLimits field, type, lowest allowed, highest allowed)
_OPTIONS: dict[str, tuple[str, type, float, float]] = {
    "port": ("port", int, 0, 65535),
    "hz": ("hz", float, 1, 1000),
    "viewer_port": ("viewer_port", int, 0, 65535),
    "max_line": ("max_line", int, *bounds("text", "max_line")),
    "max_clients": ("max_clients", int, *bounds("text", "max_clients")),
    "max_unread": ("max_unread", int, *bounds("text", "max_unread")),
    "partial_timeout": ("partial_timeout_s", float, *bounds("text", "partial_timeout_s")),
    "max_sleep": ("max_sleep_s", float, *bounds("text", "max_sleep_s")),
    "speed": ("speed", float, 1, 100),
    "lspeed": ("lspeed", float, 0.001, 5),
    "trail_points": ("trail_points", int, 16, 10_000_000),
    "max_objects": ("max_objects", int, 0, 10_000),
    "max_viewers": ("max_viewers", int, *bounds("page", "max_clients")),
    "rosbridge_port": ("rosbridge_port", int, 0, 65535),
    "plan_timeout": ("plan_timeout_s", float, 0.001, 60),
    "seed": ("plan_seed", int, 0, 2**31 - 2),
    "plan_step": ("plan_step_deg", float, 0.01, 10),
    "plan_tool_step": ("plan_tool_step_mm", float, 0.1, 100),
    "crcl_port": ("crcl_port", int, 0, 65535),
}
_TO_SI = {  # a setting given in handier units -> (SessionDefaults field, conversion)
    "plan_step_deg": ("plan_step_rad", math.radians),
    "plan_tool_step_mm": ("plan_tool_step_m", lambda mm: mm / 1000.0),
}
_TEXT_OPTIONS = (
    "host",
    "viewer_host",
    "robot",
    "motion",
    "guard",
    "record_dir",
    "viewer_token",
    "viewer_origins",
    "clock",
    "page_process",
    "viewer_lighting",
)
_CHOICES = {
    "motion": ("off", "on", "follow"),
    "guard": ("off", "on", "plan"),
    "page_process": ("off", "on"),
    "viewer_lighting": ("studio", "plain"),
}
LIGHTINGS = _CHOICES["viewer_lighting"]
"""How the page may light its scene (``--viewer-lighting``; ``view.adapter.LIGHTINGS``)."""
MOTION_FLAGS = ("max_velocity", "max_acceleration", "max_jerk")
"""Motion limits a flag may give every robot (over the ini's)."""
_EXTRA_KEYS = ["tool", "gripper", *MOTION_FLAGS]
ROBOT_KEYS = ["base", "eelink", "urdf", "package_path", "xacro_args", *_EXTRA_KEYS]
_MEMBER_PLACE_KEYS = ("origin", "port")  # a cell member's, beside its robot keys (members.py)
_LIMIT_FIELDS = {f for f in ServerLimits.__dataclass_fields__}
_SESSION_FIELDS = {f for f in SessionDefaults.__dataclass_fields__}


def _read_ini(path: Path) -> tuple[dict[str, Any], dict[str, RobotEntry]]:
    parser = read_ini(path)
    values: dict[str, Any] = {}
    if parser.has_section("options"):
        for key, text in parser.items("options"):
            if key in _OPTIONS:
                name, kind, low, high = _OPTIONS[key]
                values[name] = number(f"[options] {key}", text, kind, low, high)
            elif key in _TEXT_OPTIONS:
                if text not in _CHOICES.get(key, (text,)):
                    raise ConfigError(f"[options] {key} = {text!r} is not one", _CHOICES[key])
                if key == "guard":
                    values[key], values["plan_around"] = text != "off", text == "plan"
                elif key == "record_dir":
                    values[key] = path.parent / text
                elif key == "viewer_origins":
                    values[key] = tuple(text.split())
                elif key == "page_process":
                    values[key] = text == "on"
                else:
                    values[key] = text
            else:
                raise ConfigError(
                    f"unknown key {key!r} in [options] of {path}",
                    sorted([*_OPTIONS, *_TEXT_OPTIONS]),
                )
    robots = {}
    members = {  # sections a cell names: they may also say where the robot stands
        name
        for section in parser.sections()
        if section.startswith("cell:")
        for name in parser.get(section, "robots", fallback="").split()
    }
    for section in parser.sections():
        if section in ("options", "objects", "faults", "parts", "cameras") or section.startswith(
            ("cell:", "objects:", "faults:", "parts:")
        ):
            continue
        items = dict(parser.items(section))
        if "robot" in items:  # a member of a cell (see members.py), not a robot of its own
            continue
        if section in members:
            items = {k: v for k, v in items.items() if k not in _MEMBER_PLACE_KEYS}
        unknown = set(items) - set(ROBOT_KEYS)
        if unknown:
            raise ConfigError(
                f"unknown key {sorted(unknown)[0]!r} in [{section}] of {path}", ROBOT_KEYS
            )
        urdf = items.get("urdf")
        if not urdf:
            raise ConfigError(f"[{section}] of {path} has no urdf = PATH")
        robots[section] = RobotEntry(
            section,
            (path.parent / urdf).resolve(),
            items.get("base"),
            items.get("eelink"),
            _package_paths(items.get("package_path", ""), path),
            tuple(items.get("xacro_args", "").split()),
            path,
            tuple((key, items[key]) for key in _EXTRA_KEYS if key in items),
        )
    return values, robots


BUNDLED_INI = PROJECT_DIR / INI_NAME
"""The project's own ini: its robot sections are the bundled robots."""


def bundled_robots() -> dict[str, RobotEntry]:
    """The bundled robots (the robot sections of the project's own ini)."""
    return _read_ini(BUNDLED_INI)[1] if BUNDLED_INI.is_file() else {}


def read_robots(ini: Path | None) -> dict[str, RobotEntry]:
    """The robots an ini can name: the bundled ones, then ``ini``'s own sections, which win
    on a name clash (``replaced_bundled`` says which did)."""
    robots = bundled_robots()
    if ini is not None and not _is_bundled_ini(ini):
        robots.update(_read_ini(ini)[1])
    return robots


def replaced_bundled(robots: Mapping[str, RobotEntry]) -> list[str]:
    """The bundled robots whose name a user's ini section took with another robot (another
    URDF or other chain ends; a copy of the bundled section, or one that adds a tool, is
    the same robot)."""
    bundled = bundled_robots()

    def same(a: RobotEntry, b: RobotEntry) -> bool:
        return (a.urdf, a.base, a.eelink) == (b.urdf, b.base, b.eelink)

    return [
        name
        for name, entry in robots.items()
        if name in bundled
        and entry.ini is not None
        and not _is_bundled_ini(entry.ini)
        and not same(entry, bundled[name])
    ]


def _is_bundled_ini(ini: Path) -> bool:
    try:
        return ini.resolve() == BUNDLED_INI.resolve()
    except OSError:
        return False


def load_settings(ini: Path | None, overrides: Mapping[str, Any]) -> Settings:
    """Merge defaults, the ini file and ``overrides`` (flags; None means not given).

    Raises:
        ConfigError: a bad ini value, or a robot name with no section.
    """
    values: dict[str, Any] = {}
    if ini is not None:
        values, _ = _read_ini(ini)
    robots = read_robots(ini)
    given = {k: v for k, v in overrides.items() if v is not None}
    for key, (name, _kind, low, high) in _OPTIONS.items():
        if name in given and not low <= given[name] <= high:
            flag = "--" + key.replace("viewer_", "viser_").replace("_", "-")
            raise ConfigError(f"{flag} {given[name]:g} is outside {low:g}..{high:g}")
    if "guard" in given:
        given["guard"], given["plan_around"] = given["guard"] != "off", given["guard"] == "plan"
    values.update(given)
    for key, (name, to_si) in _TO_SI.items():
        if key in values:
            values[name] = to_si(values.pop(key))
    if "record_dir" in values:
        values["record_dir"] = Path(values["record_dir"])
    if "clock" in values:  # a bad clock stops the program here, naming the forms
        parse_clock(values["clock"], "--clock" if "clock" in given else "[options] clock")
    for key in ("package_paths", "xacro_args", "viewer_origins"):
        values[key] = tuple(values.get(key, ()))
    values["viewer_port_named"] = "viewer_port" in values
    limit_values = {k: values.pop(k) for k in list(values) if k in _LIMIT_FIELDS}
    session_values = {k: values.pop(k) for k in list(values) if k in _SESSION_FIELDS}
    settings = replace(
        Settings(),
        **values,
        limits=ServerLimits(**limit_values),
        session=SessionDefaults(**session_values),
        robots=robots,
        ini=ini,
    )
    if settings.urdf is None:
        entry = find_robot(settings.robot, robots, ini)
        if settings.robot in robots:
            robots[settings.robot].check_package_paths()
        settings = replace(
            settings,
            urdf=entry.urdf,
            base=settings.base or entry.base,
            eelink=settings.eelink or entry.eelink,
            package_paths=(*settings.package_paths, *entry.package_paths),
            xacro_args=(*entry.xacro_args, *settings.xacro_args),
        )
    elif "robot" in overrides and overrides["robot"] is not None:
        found = catalogue(robots, ini).get(settings.robot)
        if found is not None:
            settings = replace(
                settings, base=settings.base or found.base, eelink=settings.eelink or found.eelink
            )
    return settings
