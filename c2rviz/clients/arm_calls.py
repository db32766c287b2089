"""The calls of planning, the guard's modes, the gripper, the ghost and faults
(docs/faults.md) (pure: arguments checked before anything is sent), and the plan's and
the faults' records; the clients' methods that send them are in ``aio_verbs`` (and its
blocking twin, ``verbs``).

Angles and a fault's noise are in the connection's unit (radians unless the client chose
degrees), lengths in metres, times in seconds (of the server's clock), a fault's latency
in milliseconds.
"""

from __future__ import annotations

from typing import NamedTuple

from ..protocol.verbs.faults import FAULT_KINDS
from . import arguments as check
from . import records as read
from .calls import Call, fixed, parsed, pose_text, with_value

__all__ = ["FAULTS", "PlanSummary", "RESET", "clear_faults", "fault", "read_faults"]


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


def read_faults(reply: str) -> list[str]:
    """``ok none`` -> []; ``ok estop since 1.500; noise 0.01 at 5.000`` -> each item."""
    if not reply.startswith("ok "):
        raise ValueError(reply)
    body = reply[3:]
    return [] if body == "none" else body.split("; ")


def fault(kind: object, args: tuple[object, ...], at: object, after: object) -> Call[None]:
    chosen = check.choice("fault", "kind", kind, tuple(FAULT_KINDS))
    words = ["fault"]
    if at is not None:
        words += ["at", repr(check.number("fault", "at", at))]
    if after is not None:
        words += ["after", repr(check.number("fault", "after", after))]
    words.append(chosen)
    if args:
        if not any(isinstance(a, str) for a in args):
            words.append(",".join(repr(check.number("fault", "args", a)) for a in args))
        else:
            words.extend(str(a) for a in args)
    return Call(parsed("fault", "args", " ".join(words)), read.read_ok)


def clear_faults(kind: object) -> Call[None]:
    chosen = check.choice("clear_faults", "kind", kind, (*FAULT_KINDS, "all"))
    return Call(f"fault clear {chosen}", read.read_ok)


FAULTS = fixed("faults", read_faults)
RESET = fixed("reset", read.read_ok)
