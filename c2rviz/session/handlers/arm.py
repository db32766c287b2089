"""What the verbs that move the arm by its joints do: ``rand``, ``home``, ``joints``,
``move`` and ``degrees``/``radians`` (``protocol.verbs.joints``); this connection's
``motion`` mode and ``speed``, ``stop``, ``wait``, ``target``, ``status``
(``protocol.verbs.motion``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ...errors import JointCountError, JointIndexError
from ...protocol import replies
from ...protocol.registry import Reply, handler
from ...protocol.verbs.joints import Home, Joints, Move, Rand, Units
from ...protocol.verbs.motion import MotionMode, Speed, Status, Stop, Target, Wait
from ..guarded import guarded_rand

if TYPE_CHECKING:
    from ..session import Session


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


@handler(MotionMode)
def motion_mode(session: Session, command: MotionMode) -> str:
    if command.mode is None:
        return replies.ok(session.motion)
    session.motion = command.mode
    return replies.OK


@handler(Speed)
def speed(session: Session, command: Speed) -> str:
    if command.percent is None:
        return replies.ok(replies.numbers([session.speed]))
    session.speed = command.percent
    return replies.OK


@handler(Stop)
def stop(session: Session, command: Stop) -> Reply:
    return session.stop()


@handler(Wait)
def wait(session: Session, command: Wait) -> Reply:
    at_rest = session.world.travels.rest(session.state)
    return replies.OK if at_rest is None else at_rest


@handler(Target)
def target(session: Session, command: Target) -> str:
    return replies.ok(replies.numbers(session.from_si(session.state.target)))


@handler(Status)
def status(session: Session, command: Status) -> str:
    left = session.world.travels.seconds_left(session.state)
    return replies.ok(f"moving {left:.3f}" if session.travel.active else "idle")
