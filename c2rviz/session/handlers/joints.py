"""What the joint verbs do: rand, home, degrees/radians, joints, move."""

from __future__ import annotations

from typing import TYPE_CHECKING

from ...errors import JointCountError, JointIndexError
from ...protocol import replies
from ...protocol.registry import Reply, handler
from ...protocol.verbs.joints import Home, Joints, Move, Rand, Units
from ..guarded import guarded_rand

if TYPE_CHECKING:
    from ..session import Session

__all__: list[str] = []


@handler(Rand)
def rand(session: Session, command: Rand) -> Reply:
    if session.guard:  # a configuration that collides with nothing, drawn off the loop
        return guarded_rand(session)
    return session.go(session.robot.random(session.services.rng))


@handler(Home)
def home(session: Session, command: Home) -> Reply:
    return session.go(session.robot.home)


@handler(Units)
def units(session: Session, command: Units) -> str:
    session.set_degrees(command.degrees)
    return replies.OK


@handler(Joints)
def joints(session: Session, command: Joints) -> Reply:
    values = command.values
    n = session.n
    if len(values) != n:
        raise JointCountError(n, len(values))
    table = session.table
    # The hot path (a stream of `joints` lines): all within limits, checked in C.
    within = table.within(values)
    return session.go(table.to_si(values) if within else session.to_si(range(n), values))


@handler(Move)
def move(session: Session, command: Move) -> Reply:
    n = session.n
    for index in command.indices:
        if index >= n:
            raise JointIndexError(index, session.state.name, n)
    q = list(session.state.target)
    for index, value in zip(command.indices, session.to_si(command.indices, command.values)):
        q[index] = value
    return session.go(q)
