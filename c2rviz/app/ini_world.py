"""What the ini adds to the world: to each robot its tool, motion limits, gripper and
workcell objects; beside the robots, parts, logical cameras and faults.

A robot section may set ``tool = x,y,z,roll,pitch,yaw`` (m, deg), ``max_velocity``,
``max_acceleration``, ``max_jerk`` (one number for every joint, or one per joint,
comma-separated; rad or m per s, s², s³) and ``gripper = JOINT:CLOSED:OPEN ...`` (finger
joints off the chain, each with its closed and open value, m or deg; ``none``: no gripper,
even if the URDF has finger joints). Workcell objects come from ``[objects]`` (the first
robot's) and ``[objects:NAME]`` (robot NAME's, for a cell), one per line, placed in that
robot's base frame::

    [objects]
    table = box 1.2,0.8,0.05  0.6,0,-0.03,0,0,0      # size (m), pose (m, deg)
    post = cylinder 0.05,0.6  0.5,0.4,0.3,0,0,0  0.8,0.3,0.2,0.6  # optional r,g,b,a
    fixture = mesh meshes/fixture.stl  0.5,-0.3,0,0,0,90  1,1,1  # mesh: file, pose, scale

Mesh files (relative to the ini) can only come from here, never from a client.

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

Every bad value is a ``ConfigError`` naming the section and key.
"""

from __future__ import annotations

import configparser
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin

from ..errors import C2rvizError, ConfigError
from ..motion.limits import MotionLimits, motion_limits
from ..protocol.verbs.faults import FaultVerb
from ..robot.gripper import Gripper, make_gripper
from ..robot.model import Robot
from ..world.cameras import DEFAULT_FOV_RAD, DEFAULT_RANGE_M, MAX_RATE_HZ, Camera
from ..world.faults import Fault, to_fault
from ..world.part_rules import make_vacuum
from ..world.world import World

IniObject = tuple[str, str, list[float], pin.SE3, "tuple[float, ...] | None", "Path | None"]
"""name, shape, size, placement in the base frame, rgba (None: default), mesh file."""


def pose_from(where: str, text: str) -> pin.SE3:
    """``x,y,z,roll,pitch,yaw`` (m, deg) as an SE3."""
    values = ini_numbers(where, text)
    if len(values) != 6:
        raise ConfigError(f"{where} = {text!r} must be 6 numbers: x,y,z (m),roll,pitch,yaw (deg)")
    x, y, z, roll, pitch, yaw = values
    rotation = pin.rpy.rpyToMatrix(*(math.radians(a) for a in (roll, pitch, yaw)))
    return pin.SE3(rotation, np.array([x, y, z]))


def tool_from(section: str, extras: Mapping[str, str]) -> pin.SE3 | None:
    """The section's ``tool``, if it sets one."""
    text = extras.get("tool")
    return None if text is None else pose_from(f"[{section}] tool", text)


def gripper_from(section: str, extras: Mapping[str, str], robot: Robot) -> Gripper | None:
    """The robot's gripper: the section's ``gripper`` if it sets one, else the URDF's.

    Raises:
        ConfigError: a malformed entry, or a joint that cannot be a finger.
    """
    text = extras.get("gripper")
    if text is None:
        return robot.gripper
    if text.strip().lower() == "none":
        return None
    if text.strip().lower() == "vacuum":
        return make_vacuum(robot.eelink)
    where = f"[{section}] gripper"
    joints: list[tuple[str, float, float]] = []
    for entry in text.split():
        name, _, values = entry.partition(":")
        numbers = ini_numbers(where, values.replace(":", ",")) if values else []
        if not name or len(numbers) != 2:
            raise ConfigError(
                f"{where} = {text!r}: {entry!r} must be JOINT:CLOSED:OPEN (m, or deg for a "
                "revolute joint), e.g. finger_joint:0:0.04; or none"
            )
        if name in robot.joint_names:
            raise ConfigError(f"{where}: {name!r} is a joint of the chain, not a finger")
        prismatic = _prismatic(robot, name)
        scale = 1.0 if prismatic else math.pi / 180.0
        joints.append((name, numbers[0] * scale, numbers[1] * scale))
    try:
        return make_gripper(robot.model, joints, robot.neutral)
    except C2rvizError as exc:
        raise ConfigError(f"{where}: {exc}") from None


def _prismatic(robot: Robot, joint: str) -> bool:
    names = list(robot.model.names)
    return joint in names and robot.model.joints[names.index(joint)].shortname().startswith(
        "JointModelP"
    )


def limits_from(section: str, extras: Mapping[str, str], robot: Robot) -> MotionLimits:
    """The robot's motion limits, with the section's overrides."""
    given: dict[str, float | Sequence[float]] = {}
    for key in ("max_velocity", "max_acceleration", "max_jerk"):
        if key in extras:
            values = ini_numbers(f"[{section}] {key}", extras[key])
            given[key] = values[0] if len(values) == 1 else values
    try:
        return motion_limits(robot, **given)  # type: ignore[arg-type]
    except C2rvizError as exc:
        raise ConfigError(f"[{section}] {exc}") from None


def ini_objects(
    ini: Path, robot: str, first: bool
) -> list[tuple[str, str, list[float], pin.SE3, tuple[float, ...] | None, Path | None]]:
    """The objects the ini places around ``robot`` (``[objects]`` too when it is the first
    robot): name, shape, size, placement, rgba, mesh path. Checked again when set."""
    found: list[IniObject] = []
    for where, name, text in ini_entries(ini, "objects", robot, first):
        words = text.split()
        if len(words) < 3:
            raise ConfigError(f"{where} = {text!r} needs a shape, a size and a pose")
        shape = words[0].lower()
        rgba: tuple[float, ...] | None = None
        mesh: Path | None = None
        if shape == "mesh":
            mesh = (ini.parent / words[1]).resolve()
            placement = pose_from(where, words[2])
            size = ini_numbers(where, words[3]) if len(words) > 3 else [1.0, 1.0, 1.0]
        else:
            size = ini_numbers(where, words[1])
            placement = pose_from(where, words[2])
            rgba = tuple(ini_numbers(where, words[3])) if len(words) > 3 else None
        found.append((name, shape, size, placement, rgba, mesh))
    return found


def ini_entries(
    ini: Path, kind: str, robot: str | None = None, first: bool = True
) -> list[tuple[str, str, str]]:
    """Each ``name = text`` of the ini's ``[KIND]`` (with ``first``: the first robot's, or a
    world's when ``robot`` is None) and ``[KIND:ROBOT]``, with where it stands
    (``[KIND] name``, for errors), in the file's order."""
    parser = configparser.ConfigParser(interpolation=None, inline_comment_prefixes=("#", ";"))
    parser.read(ini, encoding="utf-8")
    sections = ([kind] if first else []) + ([f"{kind}:{robot}"] if robot is not None else [])
    return [
        (f"[{section}] {name}", name, text)
        for section in sections
        if parser.has_section(section)
        for name, text in parser.items(section)
    ]


def ini_numbers(where: str, text: str) -> list[float]:
    """``text`` (``a,b,c``) as finite numbers, or a ``ConfigError`` saying ``where``."""
    try:
        values = [float(part) for part in text.split(",")]
    except ValueError:
        raise ConfigError(f"{where} = {text!r} is not a comma-separated list of numbers") from None
    if not all(map(math.isfinite, values)):
        raise ConfigError(f"{where} = {text!r} has a value that is not a finite number")
    return values


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
