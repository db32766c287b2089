"""What a ``TestServer`` is started with: the program's settings for a test's options, and
the robots, loaded once per set of options that changes them and kept for the next server
(loading a URDF is most of a start), or built by the test itself."""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from typing import Any

import pinocchio as pin

from ..app.config import MOTION_FLAGS, Settings, load_settings
from ..app.members import Member, members
from ..ini import find_ini
from ..motion.limits import motion_limits
from ..robot.model import Robot
from ..world.clock import Clock

RUNTIME_OPTIONS = (
    "clock",
    "viewer",
    "doors",
    "crcl",
    "rosbridge",
    "limits",
    "record",
    "motion",
    "speed",
    "guard",
    "lspeed",
    "faults",
)
"""Options that do not change which robots are loaded (the rest key the robot cache)."""
_loaded: dict[str, tuple[list[Member], str | None]] = {}
_in_use: set[str] = set()


_NOT_FLAGS = ("ini", "doors", "record", "faults", "limits")
"""Options that are not ``Settings`` fields (``clock`` is one, unless a clock object)."""


def settings_for(options: Mapping[str, Any], read_ini: bool = True) -> Settings:
    """The program's settings for ``options``: flag names as keys (``robot``, ``cell``,
    ``ini``, ``clock``, ``motion``, ``max_objects``...), every port free, no page unless
    ``viewer=True``, no door but those asked (``doors=True`` every one, ``crcl=True``,
    ``rosbridge=True``); with ``read_ini=False`` no ini unless ``ini`` names one."""
    given = {k: v for k, v in options.items() if k not in _NOT_FLAGS}
    if isinstance(given.get("clock"), Clock):
        del given["clock"]  # a clock object: the server uses it as it is
    doors = bool(options.get("doors"))
    ports = {name: 0 for name in Settings.__dataclass_fields__ if name.endswith("port")}
    overrides: dict[str, Any] = {**ports, "viewer": False, "crcl": doors, "rosbridge": doors}
    motion = {k: given.pop(k) for k in MOTION_FLAGS if k in given}  # the flags' own text
    overrides.update(given)
    if motion:
        overrides["motion_flags"] = tuple((k, str(v)) for k, v in motion.items())
    overrides["robot_flag"] = "robot" in given
    overrides["urdf_flag"] = "urdf" in given
    ini = find_ini(options.get("ini")) if read_ini or "ini" in options else None
    settings = load_settings(ini, overrides)
    if options.get("limits") is not None:
        settings = dataclasses.replace(settings, limits=options["limits"])
    return settings


def take_members(
    options: Mapping[str, Any], settings: Settings
) -> tuple[list[Member], str | None, str | None]:
    """The robots ``settings`` name and the cell's name, from the cache when no other
    server uses that entry (else loaded afresh), and the entry's key to ``give_back`` (None:
    not the cache's)."""
    key = repr(sorted((k, v) for k, v in options.items() if k not in RUNTIME_OPTIONS))
    loaded = None
    if key in _in_use or key not in _loaded:
        loaded = members(settings)
        _loaded.setdefault(key, loaded)
    taken: str | None = None
    if key not in _in_use:
        loaded = _loaded[key]
        taken = key
        _in_use.add(key)
    assert loaded is not None
    return [dataclasses.replace(m, port=0) for m in loaded[0]], loaded[1], taken


def give_back(key: str | None) -> None:
    """The server that took the cache's entry ``key`` is done with it."""
    if key is not None:
        _in_use.discard(key)


def given_members(robots: Robot | Mapping[str, Robot]) -> list[Member]:
    """Members for robots a test built: at the world's origin, their URDF's limits."""
    named = {robots.name: robots} if isinstance(robots, Robot) else dict(robots)
    return [
        Member(name, robot, pin.SE3.Identity(), 0, motion_limits(robot))
        for name, robot in named.items()
    ]
