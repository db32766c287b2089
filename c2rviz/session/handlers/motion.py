"""What the motion verbs do: this connection's mode and speed, stop, wait, and asking."""

from __future__ import annotations

from typing import TYPE_CHECKING

from ...planning.cancel import STOPPED
from ...protocol import replies
from ...protocol.registry import Reply, handler
from ...protocol.verbs.motion import MotionMode, Speed, Status, Stop, Target, Wait

if TYPE_CHECKING:
    from ..session import Session

__all__: list[str] = []


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
    session.services.worker.cancel(session, STOPPED)  # its plans searching, if any
    at_rest = session.world.travels.stop(session.state, session.source)
    return replies.OK if at_rest is None else at_rest


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
