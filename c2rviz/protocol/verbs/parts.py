"""Part verbs: the gripper (``grip``, registered first), parts it picks and places, goals
for them, and a score; then logical cameras that report the parts they see
(docs/cameras.md).
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from ...errors import BadArguments, shown
from ..grammar import ANGLE_LIMIT, check_pose, count, numbers, numbers_arg
from ..registry import usage, verb


@verb(
    "grip",
    "[S]",
    "the gripper to S, 0 closed .. 1 open, travelling as `motion` says (a robot with no "
    "gripper gets an error); closing on a part grasps it and replies the opening where the "
    "fingers stop, opening releases it (docs/parts.md); alone, reply its opening",
    examples=("grip", "grip 0.25"),
)
@dataclass(frozen=True, slots=True)
class Grip:
    """Move (or, with None, ask) the gripper's opening, 0 closed .. 1 open."""

    opening: float | None

    @staticmethod
    def parse(verb: str, words: list[str]) -> Grip:
        if not words:
            return Grip(None)
        (opening,) = numbers_arg(verb, words, 1)
        if not 0.0 <= opening <= 1.0:
            raise BadArguments(verb, f"{opening:g} is outside 0..1", usage(verb))
        return Grip(opening)


_NAME = re.compile(r"[A-Za-z0-9_.-]{1,64}")
# shape -> (how many size values, whether the pose has an orientation)
_SHAPES = {"box": (3, True), "sphere": (1, False), "cylinder": (2, True)}
PART_SIZE_M = (0.001, 2.0)  # world.parts.PART_SIZE_M (the protocol may not import world)

Pose = tuple[float, float, float, float, float, float]


@dataclass(frozen=True, slots=True)
class PartEdit:
    """Add part ``name`` (size [m]; pose x, y, z [m], roll, pitch, yaw [client's angle
    unit], in the robot's base frame), ``remove`` it (``all``: every one), or with
    shape ``""`` ask where it is."""

    name: str
    shape: str
    size: tuple[float, ...] = ()
    pose: Pose = (0.0,) * 6
    kind: str | None = None
    rgb: tuple[float, float, float] | None = None


def _name(verb_name: str, name: str, what: str = "part") -> str:
    if _NAME.fullmatch(name) is None:
        raise BadArguments(
            verb_name,
            f"bad {what} name {shown(name)}: use letters, digits, _ . - (at most 64)",
            usage(verb_name),
        )
    return name


def _options(verb_name: str, words: list[str]) -> tuple[str | None, tuple[float, ...] | None]:
    kind: str | None = None
    rgb: tuple[float, ...] | None = None
    for word in words:
        key, _, value = word.partition("=")
        if key.lower() == "type" and value:
            kind = _name(verb_name, value, "type")
        elif key.lower() in ("color", "colour") and value:
            rgb = count(verb_name, numbers(verb_name, value), 3)
            if not all(0.0 <= c <= 1.0 for c in rgb):
                raise BadArguments(verb_name, "color takes r,g,b each in 0..1", usage(verb_name))
        else:
            raise BadArguments(
                verb_name,
                f"{shown(word)} is not type=TYPE or color=r,g,b",
                usage(verb_name),
            )
    return kind, rgb


def _parse_part(verb_name: str, words: list[str]) -> PartEdit:
    if not words:
        raise BadArguments(verb_name, "needs a name", usage(verb_name))
    name = words[0]
    if name == "all" and words[1:] == ["remove"]:
        return PartEdit("all", "remove")
    _name(verb_name, name)
    if name == "all":
        raise BadArguments(
            verb_name, "'all' is not a part name (all remove clears)", usage(verb_name)
        )
    if len(words) == 1:
        return PartEdit(name, "")
    kind = words[1].lower()
    if kind == "remove":
        if len(words) != 2:
            raise BadArguments(verb_name, "remove takes nothing more", usage(verb_name))
        return PartEdit(name, "remove")
    if kind not in _SHAPES:
        raise BadArguments(
            verb_name,
            f"unknown shape {shown(kind)}; choose box, cylinder or sphere",
            usage(verb_name),
        )
    sizes, oriented = _SHAPES[kind]
    if len(words) < 4:
        raise BadArguments(verb_name, f"{kind} takes a size and a pose", usage(verb_name))
    size = count(verb_name, numbers(verb_name, words[2]), sizes)
    low, high = PART_SIZE_M
    for value in size:
        if not low <= value <= high:
            raise BadArguments(
                verb_name, f"part size {value:g} m is outside {low:g}..{high:g} m", usage(verb_name)
            )
    pose = numbers(verb_name, words[3])
    if not oriented and len(pose) == 3:
        pose = (*pose, 0.0, 0.0, 0.0)
    x, y, z, roll, pitch, yaw = count(verb_name, pose, 6)
    check_pose(verb_name, (x, y, z, roll, pitch, yaw))
    part_kind, rgb = _options(verb_name, words[4:])
    colour = None if rgb is None else (rgb[0], rgb[1], rgb[2])
    return PartEdit(name, kind, size, (x, y, z, roll, pitch, yaw), part_kind, colour)


verb(
    "part",
    "NAME box sx,sy,sz x,y,z,roll,pitch,yaw [type=T] [color=r,g,b] | "
    "NAME cylinder r,length x,y,z,roll,pitch,yaw [...] | NAME sphere r x,y,z [...] | "
    "NAME remove | NAME",
    "add a part a gripper can pick (base frame, metres, angles in the connection's unit; "
    "docs/parts.md), remove it (`part all remove`: every one), or alone reply its pose and "
    "state: `ok x,y,z,roll,pitch,yaw free|held|resting on OBJECT`",
    parse=_parse_part,
    examples=(
        "part p1 box 0.03,0.03,0.03 0.5,0,0.015,0,0,0 type=cube color=1,0,0",
        "part p1",
        "part p1 remove",
    ),
)(PartEdit)


@verb(
    "parts",
    "",
    "reply every part: `ok NAME:x,y,z,roll,pitch,yaw:STATE;...` (base frame; `ok none`)",
    examples=("parts",),
)
@dataclass(frozen=True, slots=True)
class PartsQuery:
    """Ask for every part's pose and state."""


@dataclass(frozen=True, slots=True)
class GoalEdit:
    """Set where part ``key`` (or any part of type ``type=T``) should end, with its
    tolerances (None: the defaults), or ``remove`` it (``all``: every goal)."""

    key: str
    remove: bool = False
    pose: Pose = (0.0,) * 6
    tol_m: float | None = None
    tol_angle: float | None = None


def _parse_goal(verb_name: str, words: list[str]) -> GoalEdit:
    if not words:
        raise BadArguments(verb_name, "needs a part name (or type=T) and a pose", usage(verb_name))
    key = words[0]
    if key.lower().startswith("type="):
        key = "type=" + _name(verb_name, key[5:], "type")
    elif not (key == "all" and words[1:] == ["remove"]):
        _name(verb_name, key)
    if words[1:] == ["remove"]:
        return GoalEdit(key, remove=True)
    if len(words) not in (2, 3):
        raise BadArguments(verb_name, "takes a pose and maybe TOL_M,TOL_ANGLE", usage(verb_name))
    pose = count(verb_name, numbers(verb_name, words[1]), 6)
    check_pose(verb_name, pose)
    x, y, z, roll, pitch, yaw = pose
    if len(words) == 2:
        return GoalEdit(key, False, (x, y, z, roll, pitch, yaw))
    tol_m, tol_angle = count(verb_name, numbers(verb_name, words[2]), 2)
    if not (0.0 < tol_m <= 1.0 and 0.0 < tol_angle <= ANGLE_LIMIT):
        raise BadArguments(
            verb_name, "tolerances must be > 0: TOL_M at most 1 m, then TOL_ANGLE", usage(verb_name)
        )
    return GoalEdit(key, False, (x, y, z, roll, pitch, yaw), tol_m, tol_angle)


verb(
    "goal",
    "NAME|type=T x,y,z,roll,pitch,yaw [TOL_M,TOL_ANGLE] | NAME remove | all remove",
    "say where a part (or any part of a type) should end (base frame; tolerances default "
    "to 5 mm and 5 degrees); `score` tells how far each is",
    parse=_parse_goal,
    examples=("goal p1 0.5,0,0.015,0,0,0", "goal all remove"),
)(GoalEdit)


@verb(
    "score",
    "",
    "reply how many goals are met and how far off the others are: "
    "`ok 3/4 met; p2 12.1 mm 3.0 deg off; p4 missing` (`ok no goals`)",
    examples=("score",),
)
@dataclass(frozen=True, slots=True)
class Score:
    """Ask for the goals' score."""


MAX_CAMERA_RATE_HZ = 100.0  # world.cameras.MAX_RATE_HZ (the protocol may not import world)
MAX_SIGMA_M = 1.0
"""The most position noise a camera may have [m]."""
CAMERA_ACTIONS = ("place", "remove", "look", "rate", "noise")


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
    examples=("camera top 0,0,1,0,90,0", "camera top", "camera top rate 5"),
)(CameraEdit)


@verb(
    "cameras",
    "",
    "reply every camera: `ok NAME:x,y,z,roll,pitch,yaw:h_fov,v_fov,range:RATE;...` "
    "(world frame; `ok none`)",
    examples=("cameras",),
)
@dataclass(frozen=True, slots=True)
class CamerasQuery:
    """Ask for every camera."""
