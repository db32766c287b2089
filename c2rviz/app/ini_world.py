"""What an ini puts in the world beside the robots: parts, logical cameras and faults.

Parts: ``[parts]`` (around the first robot) and ``[parts:NAME]`` (around robot NAME of a
cell), one per line, in that robot's base frame::

    [parts]
    p1 = box 0.03,0.03,0.06  0.45,0,0.03,0,0,0  type=block  color=1,0.5,0   # m, deg
    ball = sphere 0.02  0.5,0.2,0.02,0,0,0

Shapes, sizes and options are the ``part`` verb's (docs/parts.md); each is checked
again when it is added (a part inside an object is an error that names it).

Cameras: ``[cameras]``, one per line, in the world frame (metres, degrees)::

    [cameras]
    top = 0.45,0,1.2,0,90,0                        # pose: looking straight down
    side = 0.45,-1,0.3,0,0,90  50,40,2.5  rate=5  noise=0.002,0.5

The pose, then optionally h_fov,v_fov (deg),range (m), ``rate=HZ`` and
``noise=SIGMA_M,SIGMA_DEG``: the ``camera`` verb's words (docs/cameras.md), each checked
again when the camera is placed (a bad one is an error that names it).

Faults: ``[faults]`` (the first robot's) and ``[faults:ROBOT]``, each entry a ``fault``
command's arguments, started or scheduled when the server starts::

    [faults]
    # name = what `fault` takes (radians; `at T` counts from the server's start)
    early_stop = at 5 estop
    shaky = noise 0.002
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin

from ..errors import C2rvizError, ConfigError
from ..protocol.verbs.faults import FaultVerb
from ..robot.model import Robot
from ..world.cameras import DEFAULT_FOV_RAD, DEFAULT_RANGE_M, MAX_RATE_HZ, Camera
from ..world.faults import Fault, to_fault
from ..world.world import World
from .robot_options import ini_entries, ini_numbers, pose_from

IniPart = tuple[str, str, list[float], pin.SE3, "str | None", "tuple[float, ...] | None"]
"""name, shape, size, placement in the base frame, type, rgba (None: the default)."""


def ini_parts(ini: Path, robot: str, first: bool) -> list[IniPart]:
    """The parts the ini places around ``robot`` (``[parts]`` too when it is the first)."""
    found: list[IniPart] = []
    for where, name, text in ini_entries(ini, "parts", robot, first):
        words = text.split()
        if len(words) < 3:
            raise ConfigError(f"{where} = {text!r} needs a shape, a size and a pose")
        kind: str | None = None
        rgba: tuple[float, ...] | None = None
        for word in words[3:]:
            key, _, value = word.partition("=")
            if key == "type" and value:
                kind = value
            elif key in ("color", "colour") and value:
                rgba = (*ini_numbers(where, value), 1.0)
            else:
                raise ConfigError(f"{where}: {word!r} is not type=TYPE or color=r,g,b")
        size = ini_numbers(where, words[1])
        found.append((name, words[0].lower(), size, pose_from(where, words[2]), kind, rgba))
    return found


@dataclass(frozen=True)
class IniCamera:
    """One ``[cameras]`` line: angles in radians, as a ``Camera`` takes them."""

    name: str
    pose: pin.SE3
    h_fov_rad: float = DEFAULT_FOV_RAD[0]
    v_fov_rad: float = DEFAULT_FOV_RAD[1]
    range_m: float = DEFAULT_RANGE_M
    rate_hz: float | None = None
    noise: tuple[float, float] | None = None  # sigma [m], sigma [rad]


def ini_cameras(ini: Path | None) -> list[IniCamera]:
    """The cameras of the ini's ``[cameras]`` (none without an ini or the section)."""
    if ini is None:
        return []
    found = []
    for where, name, text in ini_entries(ini, "cameras"):
        words = text.split()
        if not words:
            raise ConfigError(f"{where} needs a pose x,y,z,roll,pitch,yaw (m, deg)")
        view: list[float] = [*map(math.degrees, DEFAULT_FOV_RAD), DEFAULT_RANGE_M]
        rate: float | None = None
        noise: tuple[float, float] | None = None
        for word in words[1:]:
            key, _, value = word.partition("=")
            if not value:
                view = _numbers(where, word, 3)
            elif key == "rate":
                (rate,) = _numbers(where, value, 1)
                if not 0.0 <= rate <= MAX_RATE_HZ:
                    raise ConfigError(f"{where}: rate {rate:g} is outside 0..{MAX_RATE_HZ:g} Hz")
            elif key == "noise":
                sigma_m, sigma_deg = _numbers(where, value, 2)
                if not (0.0 <= sigma_m <= 1.0 and 0.0 <= sigma_deg <= 180.0):
                    raise ConfigError(f"{where}: noise takes 0..1 m, 0..180 deg")
                noise = (sigma_m, math.radians(sigma_deg))
            else:
                raise ConfigError(
                    f"{where}: {word!r} is not h_fov,v_fov,range or rate=HZ or noise=M,DEG"
                )
        found.append(
            IniCamera(
                name,
                pose_from(where, words[0]),
                math.radians(view[0]),
                math.radians(view[1]),
                view[2],
                rate,
                noise,
            )
        )
    return found


def place_cameras(world: World, rng: np.random.Generator, cameras: list[IniCamera]) -> None:
    """Put the ini's cameras in the world (a bad one raises ``ConfigError``)."""
    for entry in cameras:
        try:
            camera = Camera(entry.name, entry.pose, entry.h_fov_rad, entry.v_fov_rad, entry.range_m)
            if entry.rate_hz is not None:
                camera.rate_hz = entry.rate_hz
            if entry.noise is not None:
                camera.sigma_m, camera.sigma_rad = entry.noise
                camera.rng = np.random.default_rng(int(rng.integers(0, 2**63)))
            world.cameras.put(camera)
        except C2rvizError as exc:
            raise ConfigError(f"[cameras] {entry.name}: {exc}") from None


def _numbers(where: str, text: str, needed: int) -> list[float]:
    try:
        values = [float(part) for part in text.split(",")]
    except ValueError:
        raise ConfigError(f"{where}: {text!r} is not a comma-separated list of numbers") from None
    if not all(map(math.isfinite, values)) or len(values) != needed:
        raise ConfigError(f"{where}: {text!r} must be {needed} finite numbers")
    return values


IniFault = tuple[FaultVerb, Fault]
"""A fault of the ini: the command as read, and the fault it starts (SI)."""


def ini_faults(ini: Path, name: str, robot: Robot, first: bool) -> list[IniFault]:
    """The faults the ini gives robot ``name`` (``[faults]`` too when it is the first).

    Raises:
        ConfigError: an entry ``fault`` would refuse, naming it and why.
    """
    found: list[IniFault] = []
    for where, _, text in ini_entries(ini, "faults", name, first):
        try:
            command = FaultVerb.parse("fault", text.split())
            if command.spec is None:
                raise ConfigError("clear is not a fault to start")
            fault = to_fault(name, robot.joint_names, 1.0, command.spec)
        except C2rvizError as exc:
            raise ConfigError(f"{where} = {text!r}: {exc}") from None
        found.append((command, fault))
    return found


def start_faults(world: World, robot: str, commands: Sequence[IniFault]) -> None:
    """Start or schedule the ini's faults of ``robot`` (``at T``: from the server's start;
    a time already past starts it now)."""
    rules = world.faults
    for command, fault in commands:
        if command.at_s is not None:
            rules.schedule(robot, fault, rules.origin + command.at_s)
        elif command.after_s is not None:
            rules.schedule(robot, fault, world.clock.now() + command.after_s)
        else:
            rules.start(robot, fault)
