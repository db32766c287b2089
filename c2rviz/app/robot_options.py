"""What the ini adds to each robot of the world: its tool, motion limits and workcell.

A robot section may set ``tool = x,y,z,roll,pitch,yaw`` (m, deg),
``max_velocity``, ``max_acceleration``, ``max_jerk`` (one number for every
joint, or one per joint, comma-separated; rad or m per s, s², s³) and
``gripper = JOINT:CLOSED:OPEN ...`` (finger joints off the chain, each with its
closed and open value, m or deg; ``none``: no gripper, even if the URDF has
finger joints). Workcell
objects come from ``[objects]`` (the first robot's) and ``[objects:NAME]`` (robot
NAME's, for a cell), one per line, placed in that robot's base frame::

    [objects]
    table = box 1.2,0.8,0.05  0.6,0,-0.03,0,0,0      # size (m), pose (m, deg)
    post = cylinder 0.05,0.6  0.5,0.4,0.3,0,0,0  0.8,0.3,0.2,0.6  # optional r,g,b,a
    fixture = mesh meshes/fixture.stl  0.5,-0.3,0,0,0,90  1,1,1  # mesh: file, pose, scale

Mesh files (relative to the ini) can only come from here, never from a client.
Every bad value is a ``ConfigError`` naming the section and key.
"""

from __future__ import annotations

import configparser
import math
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
import pinocchio as pin

from ..errors import C2rvizError, ConfigError
from ..motion.limits import MotionLimits, motion_limits
from ..robot.gripper import Gripper, make_gripper
from ..robot.model import Robot
from ..world.grasp import make_vacuum

__all__ = [
    "IniObject",
    "gripper_from",
    "ini_entries",
    "ini_numbers",
    "ini_objects",
    "limits_from",
    "pose_from",
    "tool_from",
]

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
