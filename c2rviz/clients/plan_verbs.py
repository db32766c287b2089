"""The clients' methods for planning, the guard's modes, the gripper and the ghost: their
calls (pure: arguments checked before anything is sent) and a part of ``Client`` and of
``AsyncClient`` each.

Angles are in the connection's unit (radians unless the client chose degrees), lengths
in metres, times in seconds.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import NamedTuple, TypeVar

from . import arguments as check
from . import records as read
from .calls import Call, fixed, parsed, pose_text, speaks, with_value

__all__ = ["AsyncPlanVerbs", "PlanSummary", "PlanVerbs"]

T = TypeVar("T")

GUARD_MODES = ("on", "off", "plan")


class PlanSummary(NamedTuple):
    """A planned path: its ``waypoints``, its joint-space ``length`` in ``unit`` (``rad``
    whatever the connection's unit, as the server says) and its ``duration`` [s]."""

    waypoints: int
    length: float
    unit: str
    duration: float


def read_plan_summary(reply: str) -> PlanSummary:
    """``ok 3 waypoints 4.816 rad 3.485 s``."""
    count, word, length, unit, duration, seconds = reply.removeprefix("ok ").split(" ")
    if not reply.startswith("ok ") or word != "waypoints" or seconds != "s":
        raise ValueError(reply)
    return PlanSummary(int(count), float(length), unit, float(duration))


def read_waypoints(reply: str) -> list[tuple[float, ...]]:
    """``ok q0;q1;...``: each waypoint's joint values."""
    if not reply.startswith("ok "):
        raise ValueError(reply)
    return [tuple(map(float, q.split(","))) for q in reply[3:].split(";")]


def plan_joints(values: object) -> Call[PlanSummary]:
    given = check.values("plan_joints", "values", values)
    line = "plan joints " + check.numbers_text(given)
    return Call(line, read_plan_summary, joint_count=("plan_joints", "values", len(given)))


def plan_pose(pose: object) -> Call[PlanSummary]:
    text = pose_text("plan_pose", "pose", pose, (3, 6))
    return Call(f"plan pose {text}", read_plan_summary)


def plan_timeout(seconds: object) -> Call[float]:
    if seconds is None:
        return fixed("plan timeout", read.read_number)
    value = check.number("plan_timeout", "seconds", seconds)
    return Call(parsed("plan_timeout", "seconds", f"plan timeout {value!r}"), with_value(value))


def plan_resolution(steps: object) -> Call[tuple[float, ...]]:
    if steps is None:
        return fixed("plan resolution", read.read_numbers)
    given = check.values("plan_resolution", "steps", steps, 2)
    line = f"plan resolution {check.numbers_text(given)}"
    return Call(parsed("plan_resolution", "steps", line), with_value(given))


def guard_mode(mode: object) -> Call[str]:
    if mode is None:
        return fixed("guard", read.read_word)
    chosen = check.choice("guard_mode", "mode", mode, GUARD_MODES)
    return Call(f"guard {chosen}", with_value(chosen))


def grip(opening: object) -> Call[float]:
    if opening is None:
        return fixed("grip", read.read_number)
    value = check.number("grip", "opening", opening)
    return Call(parsed("grip", "opening", f"grip {value!r}"), with_value(value))


def ghost(on: object) -> Call[bool]:
    if on is None:
        return fixed("ghost", read.read_on_off)
    chosen = check.flag("ghost", "on", on)
    return Call(f"ghost {'on' if chosen else 'off'}", with_value(chosen))


PLAN = fixed("plan", read_waypoints)


class PlanVerbs:
    """Planning, the guard's modes, the gripper and the ghost (a part of the client)."""

    def call(self, call: Call[T]) -> T:
        raise NotImplementedError  # the client's

    @speaks("plan")
    def plan_joints(self, values: Sequence[float]) -> PlanSummary:
        """A collision-free path to joint ``values`` [rad, or deg; m]; with motion on, the
        arm moves along it (the reply comes as ``motion`` says)."""
        return self.call(plan_joints(values))

    @speaks("plan")
    def plan_pose(self, pose: Sequence[float]) -> PlanSummary:
        """A collision-free path to a tool ``pose`` (x, y, z [m], and roll, pitch, yaw
        [rad, or deg], or the position alone); moves as ``plan_joints``."""
        return self.call(plan_pose(pose))

    @speaks("plan")
    def plan(self) -> list[tuple[float, ...]]:
        """The last planned path's waypoints, each the chain's joint values [rad, or deg; m]."""
        return self.call(PLAN)

    @speaks("plan")
    def plan_timeout(self, seconds: float | None = None) -> float:
        """Set (or with None, return) this connection's planning time limit [s]."""
        return self.call(plan_timeout(seconds))

    @speaks("plan")
    def plan_resolution(self, steps: Sequence[float] | None = None) -> tuple[float, ...]:
        """Set (or with None, return) the checks' steps: (a joint's angle [rad, or deg],
        the tool's travel [m])."""
        return self.call(plan_resolution(steps))

    @speaks("guard")
    def guard_mode(self, mode: str | None = None) -> str:
        """The guard as ``on``, ``off`` or ``plan`` (a refused move is planned around);
        returns it."""
        return self.call(guard_mode(mode))

    @speaks("grip")
    def grip(self, opening: float | None = None) -> float:
        """The gripper to ``opening`` [0 closed .. 1 open] (arrives as ``motion`` says), or
        with None return its opening; returns the opening."""
        return self.call(grip(opening))

    @speaks("ghost")
    def ghost(self, on: bool | None = None) -> bool:
        """Show this connection's targets and paths as a ghost on the page (``True``, the
        default); returns whether it does."""
        return self.call(ghost(on))


class AsyncPlanVerbs:
    """``PlanVerbs`` for the async client."""

    async def call(self, call: Call[T]) -> T:
        raise NotImplementedError  # the client's

    @speaks("plan")
    async def plan_joints(self, values: Sequence[float]) -> PlanSummary:
        """As ``PlanVerbs.plan_joints``."""
        return await self.call(plan_joints(values))

    @speaks("plan")
    async def plan_pose(self, pose: Sequence[float]) -> PlanSummary:
        """As ``PlanVerbs.plan_pose``."""
        return await self.call(plan_pose(pose))

    @speaks("plan")
    async def plan(self) -> list[tuple[float, ...]]:
        """As ``PlanVerbs.plan``."""
        return await self.call(PLAN)

    @speaks("plan")
    async def plan_timeout(self, seconds: float | None = None) -> float:
        """As ``PlanVerbs.plan_timeout``."""
        return await self.call(plan_timeout(seconds))

    @speaks("plan")
    async def plan_resolution(self, steps: Sequence[float] | None = None) -> tuple[float, ...]:
        """As ``PlanVerbs.plan_resolution``."""
        return await self.call(plan_resolution(steps))

    @speaks("guard")
    async def guard_mode(self, mode: str | None = None) -> str:
        """As ``PlanVerbs.guard_mode``."""
        return await self.call(guard_mode(mode))

    @speaks("grip")
    async def grip(self, opening: float | None = None) -> float:
        """As ``PlanVerbs.grip``."""
        return await self.call(grip(opening))

    @speaks("ghost")
    async def ghost(self, on: bool | None = None) -> bool:
        """As ``PlanVerbs.ghost``."""
        return await self.call(ghost(on))
