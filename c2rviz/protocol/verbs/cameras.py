"""Camera verbs: logical cameras that report the parts they see (docs/cameras.md)."""

from __future__ import annotations

import re
from dataclasses import dataclass

from ...errors import BadArguments, shown
from ..grammar import count, numbers
from ..ranges import check_pose
from ..registry import usage, verb

__all__ = ["CAMERA_ACTIONS", "MAX_CAMERA_RATE_HZ", "CameraEdit", "CamerasQuery"]

_NAME = re.compile(r"[A-Za-z0-9_.-]{1,64}")
MAX_CAMERA_RATE_HZ = 100.0  # world.cameras.MAX_RATE_HZ (the protocol may not import world)
MAX_SIGMA_M = 1.0
"""The most position noise a camera may have [m]."""
CAMERA_ACTIONS = ("place", "remove", "look", "rate", "noise")

Pose = tuple[float, float, float, float, float, float]


@dataclass(frozen=True, slots=True)
class CameraEdit:
    """One camera verb: ``place`` camera ``name`` at ``pose`` (world frame; x, y, z [m],
    roll, pitch, yaw [client's angle unit]) with ``view`` (h_fov, v_fov [client's angle
    unit], range [m]; None: the defaults), ``remove`` it, ``look`` (what it sees now), set
    its ``rate`` [1/s] or its ``noise`` (sigma [m], sigma [client's angle unit])."""

    name: str
    action: str
    pose: Pose = (0.0,) * 6
    view: tuple[float, float, float] | None = None
    values: tuple[float, ...] = ()


def _parse_camera(verb_name: str, words: list[str]) -> CameraEdit:
    if not words:
        raise BadArguments(verb_name, "needs a camera name", usage(verb_name))
    name = words[0]
    if _NAME.fullmatch(name) is None:
        raise BadArguments(
            verb_name,
            f"bad camera name {shown(name)}: use letters, digits, _ . - (at most 64)",
            usage(verb_name),
        )
    if len(words) == 1:
        return CameraEdit(name, "look")
    action = words[1].lower()
    if action == "remove":
        if len(words) != 2:
            raise BadArguments(verb_name, "remove takes nothing more", usage(verb_name))
        return CameraEdit(name, "remove")
    if action in ("rate", "noise"):
        if len(words) != 3:
            raise BadArguments(verb_name, f"{action} takes one value", usage(verb_name))
        if action == "rate":
            (hz,) = count(verb_name, numbers(verb_name, words[2]), 1)
            if not 0.0 <= hz <= MAX_CAMERA_RATE_HZ:
                raise BadArguments(
                    verb_name,
                    f"rate {hz:g} Hz is outside 0..{MAX_CAMERA_RATE_HZ:g} (0: not in watch)",
                    usage(verb_name),
                )
            return CameraEdit(name, "rate", values=(hz,))
        sigma_m, sigma_angle = count(verb_name, numbers(verb_name, words[2]), 2)
        if not (0.0 <= sigma_m <= MAX_SIGMA_M and sigma_angle >= 0.0):
            raise BadArguments(
                verb_name,
                f"noise takes SIGMA_M in 0..{MAX_SIGMA_M:g} m and SIGMA_ANGLE >= 0",
                usage(verb_name),
            )
        return CameraEdit(name, "noise", values=(sigma_m, sigma_angle))
    if len(words) > 3:
        raise BadArguments(verb_name, "takes a pose and maybe h_fov,v_fov,range", usage(verb_name))
    pose = count(verb_name, numbers(verb_name, words[1]), 6)
    check_pose(verb_name, pose)
    x, y, z, roll, pitch, yaw = pose
    view = None
    if len(words) == 3:
        h_fov, v_fov, range_m = count(verb_name, numbers(verb_name, words[2]), 3)
        view = (h_fov, v_fov, range_m)
    return CameraEdit(name, "place", (x, y, z, roll, pitch, yaw), view)


verb(
    "camera",
    "NAME x,y,z,roll,pitch,yaw [h_fov,v_fov,range] | NAME remove | NAME rate HZ | "
    "NAME noise SIGMA_M,SIGMA_ANGLE | NAME",
    "place a logical camera (world frame, looking along its +x axis, z up; angles and "
    "fields of view in the connection's unit, default 60,45 degrees and 2 m; "
    "docs/cameras.md), remove it, set how often `watch` reports it or its noise, or alone "
    "reply what it sees now: `ok p1:TYPE:x,y,z,roll,pitch,yaw;...` in its frame (`ok none`)",
    parse=_parse_camera,
)(CameraEdit)


@verb(
    "cameras",
    "",
    "reply every camera: `ok NAME:x,y,z,roll,pitch,yaw:h_fov,v_fov,range:RATE;...` "
    "(world frame; `ok none`)",
)
@dataclass(frozen=True, slots=True)
class CamerasQuery:
    """Ask for every camera."""
