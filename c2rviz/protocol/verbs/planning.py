"""Planning verbs: a collision-free path to joint values or a tool pose, and its settings."""

from __future__ import annotations

from dataclasses import dataclass

from ...errors import BadArguments, shown
from ..grammar import numbers
from ..registry import usage, verb

__all__ = ["PLAN_FORMS", "Plan"]

PLAN_FORMS = ("joints", "pose", "timeout", "resolution")
"""What may follow ``plan``; alone it replies the last path."""


@verb(
    "plan",
    "[joints v0,...,vn-1 | pose x,y,z[,roll,pitch,yaw] | timeout [S] | resolution [A,M]]",
    "a collision-free path (around the workcell and the other robots) to joint values, or "
    "to a tool pose (position only with x,y,z), and with motion on the arm moves along it: "
    "`ok 3 waypoints 2.41 rad 3.2 s` (joint-space length, duration); alone, reply the last "
    "path's waypoints `ok q0;q1;...`; `timeout` and `resolution` set or reply this "
    "connection's search limit [s] and check steps (a joint's angle, the tool's travel [m]) "
    "(docs/planning.md)",
)
@dataclass(frozen=True, slots=True)
class Plan:
    """Plan a path (``joints``, ``pose``), set or ask a setting (``timeout``,
    ``resolution``; no values: ask), or (``show``) ask the last path's waypoints.

    Values are in the connection's units: joint values as ``joints`` takes them, a
    pose as ``moveto``, the timeout in seconds, the resolution as a joint angle and
    a tool travel in metres.
    """

    what: str
    values: tuple[float, ...] = ()

    @staticmethod
    def parse(verb: str, words: list[str]) -> Plan:
        if not words:
            return Plan("show")
        what = words[0].lower()
        if what not in PLAN_FORMS:
            raise BadArguments(
                verb, f"{shown(words[0])} is not one of {', '.join(PLAN_FORMS)}", usage(verb)
            )
        rest = words[1:]
        if len(rest) > 1:
            raise BadArguments(verb, f"{what} takes one list of values, no spaces", usage(verb))
        values = numbers(verb, rest[0]) if rest else ()
        if what in ("joints", "pose") and not values:
            raise BadArguments(verb, f"{what} needs values", usage(verb))
        if what == "pose" and len(values) not in (3, 6):
            raise BadArguments(
                verb,
                f"a pose is x,y,z or x,y,z,roll,pitch,yaw, not {len(values)} values",
                usage(verb),
            )
        if what == "timeout" and len(values) > 1:
            raise BadArguments(verb, "timeout takes one number of seconds", usage(verb))
        if what == "resolution" and len(values) not in (0, 2):
            raise BadArguments(
                verb, "resolution takes a joint step and a tool step: A,M", usage(verb)
            )
        return Plan(what, values)
