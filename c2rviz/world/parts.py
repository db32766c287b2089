"""Parts: loose things a gripper can pick, carry and place, in the world frame.

A ``Part`` is a box, cylinder or sphere (sizes as a workcell object's: a box's edges, a
cylinder's radius and length along its z axis, a sphere's radius, in metres) with a
name, a pose in the world (cell) frame, an optional type and colour, and a state:
``free`` (lying where it was put), ``held`` by a robot's gripper link (its pose follows
that link at a fixed offset) or ``resting on`` an object, another part or the floor.
``Parts`` holds them in the order they were added and checks every input; what moves
them (grasps, releases) is ``part_world.py``. No asyncio.

``Falls`` lowers parts falling straight down on the world's clock, at g, one frame at a
time. It belongs to a world's ``WorldParts``: ``start`` a part's fall of so many metres
onto something, and a timer on the clock lowers every falling part once per frame
(``z = z0 - g t² / 2``, never past where it lands), calls ``landed(part, onto)`` when it
gets there and ``stepped(done)`` after each frame (``done``: no part falls any more).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field

import coal
import numpy as np
import pinocchio as pin

from ..collision.workcell import (
    BadObjectName,
    WorkcellError,
    WorkcellObject,
    collision_geometry,
    make_object,
)
from ..errors import shown
from .clock import Clock, Timer

MAX_PARTS = 100
"""Parts in a world at once."""
PART_SIZE_M = (0.001, 2.0)
"""A part's size (edge, radius, length) [m]: a part is something a gripper lifts."""
PART_SHAPES = ("box", "cylinder", "sphere")
CHECK_MARGIN_M = 0.0005
"""Collision checks see a part this much smaller all round [m] (touching is not hitting)."""
FLOOR = "floor"
"""What a part lying on the world's floor (z = 0) rests on."""
_DEFAULT_RGBA = (0.85, 0.55, 0.2, 1.0)  # orange: apart from the grey-blue objects


class PartError(WorkcellError):
    """A part that cannot be added, found or changed."""


class PartNameInUse(PartError):
    def __init__(self, name: str, what: str) -> None:
        self.name = name
        super().__init__(f"name {shown(name)} is already {what}: remove it first")


class TooManyParts(PartError):
    def __init__(self, limit: int) -> None:
        self.limit = limit
        super().__init__(f"the world already holds {limit} parts, its limit; remove one first")


class UnknownPart(PartError):
    def __init__(self, name: str, names: Sequence[str]) -> None:
        self.name = name
        have = ", ".join(names) if names else "none"
        super().__init__(f"no part named {shown(name)} (parts: {have})")


class PartSizeError(PartError):
    def __init__(self, value: float) -> None:
        low, high = PART_SIZE_M
        super().__init__(f"part size {value:g} m is outside {low:g}..{high:g} m")


@dataclass(eq=False)
class Part:
    """One part.

    Attributes:
        obj: Its name, shape, size and colour (``obj.placement`` is where it was added).
        geometry: Its coal shape (centred on its pose).
        checked: The shape collision checks use: ``CHECK_MARGIN_M`` smaller all round, so
            a part resting on a table, or held against it, does not count as hitting it.
        pose: Its pose in the world frame now.
        kind: Its type (``type=``), or None.
        holder: The robot holding it, or None.
        link: The link it is fixed to while held.
        offset: Its pose in that link's frame while held.
        on: What it rests on (an object, a part, ``floor``), or None.
        falling: It is falling (released over nothing close below).
    """

    obj: WorkcellObject
    geometry: coal.CollisionGeometry
    checked: coal.CollisionGeometry
    pose: pin.SE3
    kind: str | None = None
    holder: str | None = None
    link: str | None = None
    offset: pin.SE3 = field(default_factory=pin.SE3.Identity)
    on: str | None = None
    falling: bool = False

    @property
    def name(self) -> str:
        return self.obj.name

    @property
    def state(self) -> str:
        """``free``, ``held`` or ``resting on NAME`` (a falling part is ``free``)."""
        if self.holder is not None:
            return "held"
        if self.on is not None and not self.falling:
            return f"resting on {self.on}"
        return "free"


def _shrunk(obj: WorkcellObject) -> coal.CollisionGeometry:
    """``obj``'s shape ``CHECK_MARGIN_M`` smaller all round (at most half its size)."""
    if obj.shape == "box":
        return coal.Box(*(max(v - 2 * CHECK_MARGIN_M, v / 2) for v in obj.size))
    if obj.shape == "cylinder":
        radius, length = obj.size
        return coal.Cylinder(
            max(radius - CHECK_MARGIN_M, radius / 2), max(length - 2 * CHECK_MARGIN_M, length / 2)
        )
    return coal.Sphere(max(obj.size[0] - CHECK_MARGIN_M, obj.size[0] / 2))


def check_part_size(size: Sequence[float]) -> None:
    """Refuse a part size outside ``PART_SIZE_M`` (``PartSizeError``)."""
    low, high = PART_SIZE_M
    for value in size:
        if not low <= value <= high:
            raise PartSizeError(value)


class Parts:
    """The parts of a world, in the order they were added."""

    def __init__(self, max_parts: int = MAX_PARTS) -> None:
        self.max_parts = max_parts
        self._parts: dict[str, Part] = {}

    def make(
        self,
        name: str,
        shape: str,
        size: Sequence[float],
        pose: pin.SE3,
        kind: str | None = None,
        rgba: Sequence[float] | None = None,
        taken: Iterable[str] = (),
    ) -> Part:
        """A checked new part (not added yet: ``add`` it once it is known to fit).

        Args:
            taken: Other names it may not take (objects, robots' links).

        Raises:
            PartError: a name in use, a bad shape or size, too many parts.
            WorkcellError: a bad name or colour.
        """
        if name in self._parts:
            raise PartNameInUse(name, "a part")
        if name in set(taken):
            raise PartNameInUse(name, "an object's or a link's")
        if shape not in PART_SHAPES:
            raise PartError(
                f"unknown part shape {shown(shape)} (choose from: {', '.join(PART_SHAPES)})"
            )
        obj = make_object(name, shape, size, pose, rgba if rgba is not None else _DEFAULT_RGBA)
        check_part_size(obj.size)
        if kind is not None and len(kind) > 64:
            raise BadObjectName(kind, "is too long for a type (64 characters)")
        if len(self._parts) >= self.max_parts:
            raise TooManyParts(self.max_parts)
        return Part(obj, collision_geometry(obj), _shrunk(obj), pin.SE3(pose), kind)

    def add(self, part: Part) -> None:
        self._parts[part.name] = part

    def remove(self, name: str) -> Part:
        """Remove one part and return it (raises ``UnknownPart``)."""
        return self._parts.pop(self.get(name).name)

    def clear(self) -> list[Part]:
        parts = list(self._parts.values())
        self._parts.clear()
        return parts

    def get(self, name: str) -> Part:
        part = self._parts.get(name)
        if part is None:
            raise UnknownPart(name, list(self._parts))
        return part

    def names(self) -> list[str]:
        return list(self._parts)

    def all(self) -> list[Part]:
        return list(self._parts.values())

    def held_by(self, robot: str) -> list[Part]:
        return [p for p in self._parts.values() if p.holder == robot]

    def __contains__(self, name: object) -> bool:
        return name in self._parts

    def __len__(self) -> int:
        return len(self._parts)


G_M_S2 = 9.81
"""A falling part's acceleration [m/s²]."""


class Falls:
    """The parts falling now, and the frame timer that lowers them."""

    def __init__(
        self,
        clock: Clock,
        frame_s: float,
        landed: Callable[[Part, str], None],
        stepped: Callable[[bool], None],
    ) -> None:
        self.clock = clock
        self.frame_s = frame_s
        self.landed = landed
        self.stepped = stepped
        self._falls: dict[str, tuple[Part, float, float, float, str]] = {}
        self._timer: Timer | None = None

    def start(self, part: Part, down_m: float, onto: str) -> None:
        """``part`` falls ``down_m`` [m] from where it is now, onto ``onto``."""
        part.falling, part.on = True, None
        z0 = float(part.pose.translation[2])
        self._falls[part.name] = (part, self.clock.now(), z0, down_m, onto)
        if self._timer is None:
            self._timer = self.clock.call_later(self.frame_s, self._tick)

    def cancel(self, name: str) -> None:
        """Part ``name`` falls no more (taken, or removed)."""
        fall = self._falls.pop(name, None)
        if fall is not None:
            fall[0].falling = False

    def stop(self) -> None:
        """The program stops: no more frames."""
        if self._timer is not None:
            self._timer.cancel()
            self._timer = None

    def _tick(self) -> None:
        self._timer = None
        t = self.clock.now()
        for name, (part, t0, z0, down, onto) in list(self._falls.items()):
            fallen = min(down, 0.5 * G_M_S2 * (t - t0) ** 2)
            part.pose = pin.SE3(
                part.pose.rotation, np.array([*part.pose.translation[:2], z0 - fallen])
            )
            if fallen >= down:
                del self._falls[name]
                part.falling = False
                self.landed(part, onto)
        self.stepped(not self._falls)
        if self._falls:
            self._timer = self.clock.call_later(self.frame_s, self._tick)
