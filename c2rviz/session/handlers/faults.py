"""What the fault verbs do: start, schedule and clear faults, list them, reset a stop.

The session turns a client's fault (its units, a joint by name or index) into the
world's (``world.faults.Fault``, SI) and hands it to ``World.faults``; everything a
fault does from then on happens at the world level, for every door alike.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ...errors import BadArguments
from ...protocol import replies
from ...protocol.registry import handler, usage
from ...protocol.verbs.faults import Faults, FaultVerb, Reset
from ...world.faults import Fault, to_fault

if TYPE_CHECKING:
    from ..session import Session


def describe(session: Session, fault: Fault) -> str:
    """``fault`` as this session reads it (noise in its angle unit)."""
    if fault.kind == "noise":
        return f"noise {replies.numbers([fault.sigma / session.angle_scale])}"
    return fault.text(session.robot.joint_names)


@handler(FaultVerb)
def fault(session: Session, command: FaultVerb) -> str:
    rules = session.world.faults
    robot = session.state.name
    if command.clear is not None:
        rules.clear(robot, command.clear)
        return replies.OK
    assert command.spec is not None
    made = to_fault(
        session.state.name, session.robot.joint_names, session.angle_scale, command.spec
    )
    now = session.world.clock.now()
    if command.at_s is not None:
        if rules.origin + command.at_s < now:
            raise BadArguments(
                "fault",
                f"T {command.at_s:g} s has passed (the world's time is {now - rules.origin:.3f} s)",
                usage("fault"),
            )
        rules.schedule(robot, made, rules.origin + command.at_s)
    elif command.after_s is not None:
        rules.schedule(robot, made, now + command.after_s)
    else:
        rules.start(robot, made)
    return replies.OK


@handler(Faults)
def faults(session: Session, command: Faults) -> str:
    listed = session.world.faults.of(session.state.name).listing(session.world.faults.origin)
    if not listed:
        return replies.ok("none")
    return replies.ok("; ".join(f"{describe(session, f)} {when}" for f, when in listed))


@handler(Reset)
def reset(session: Session, command: Reset) -> str:
    session.world.faults.reset(session.state.name)
    return replies.OK
