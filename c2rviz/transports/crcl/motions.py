"""The CRCL commands that take time, as jobs of a ``Controller`` on its session.

Each job plans first (nothing moves while it does, so a refusal moves nothing),
then marks itself moving (``Controller.moving``) and waits for the session's reply
on arrival. Moves go through the session's own planning and playing, the ones the
text port's ``moveto`` and ``movel`` use: the session's speed, ``lspeed``, guard
(on for CRCL) and the world's limits and collisions apply alike.

- ``MoveTo``: through joint space (``moveto``) or, ``MoveStraight``, along the tool's
  straight line (``movel``), which starts from rest: a move of this connection under
  way is braked first.
- ``MoveThroughTo``: every waypoint solved (or every line planned) and checked before
  the arm moves, then one after the other.
- ``ActuateJoints``: the named joints (the others keep their target) at the speed
  their ``JointSpeed``/``JointAccel`` allow within the limits.
- ``StopMotion``/``EndCanon``: the arm brakes within its limits, the fingers stop.
- ``Dwell``: a pause on the world's clock. ``SetEndEffector``: the gripper's ``grip``.
"""

from __future__ import annotations

from collections.abc import Sequence

import pinocchio as pin

from ...collision.model import segment
from ...errors import ArmMoved
from ...protocol.verbs.gripper import Grip
from ...session.handlers.cartesian import StraightPlan, plan_straight, play_straight, solve
from .controller import Controller, Job, Refused
from .primitives import Pose
from .units import pose_to_matrix

__all__ = [
    "actuate",
    "dwell",
    "grip",
    "halt",
    "move_through",
    "move_to",
    "placement",
]


def placement(pose: Pose, length_unit: str) -> pin.SE3:
    """A CRCL pose (in ``length_unit``) as a placement in the base frame [m]."""
    return pin.SE3(pose_to_matrix(pose, length_unit))


async def move_to(ctl: Controller, job: Job, target: pin.SE3, straight: bool) -> None:
    """The tool point to ``target``: along a straight line, or through joint space."""
    session = ctl.session
    if straight:
        await _at_rest(ctl, job)
        plan = await plan_straight(session, target)
        await ctl.moving(job, play_straight(session, plan))
    else:
        q = await solve(session, target)
        await ctl.moving(job, session.go(q))


async def move_through(
    ctl: Controller, job: Job, targets: Sequence[pin.SE3], straight: bool
) -> None:
    """Through every target in turn, all of them planned and checked before any move."""
    session = ctl.session
    if straight:
        await _at_rest(ctl, job)
        plans: list[StraightPlan] = []
        start: Sequence[float] | None = None
        for target in targets:
            plan = await plan_straight(session, target, start)
            plans.append(plan)
            start = plan.waypoints[-1]
        for plan in plans:
            if session.travel.active or session.state.q != plan.start:
                raise ArmMoved("the arm moved (another door drives it) between the waypoints")
            await ctl.moving(job, play_straight(session, plan))
        return
    goals: list[Sequence[float]] = []
    seed: Sequence[float] | None = None
    for target in targets:
        seed = await solve(session, target, seed)
        goals.append(seed)
    for before, after in zip(goals, goals[1:]):  # the first leg is checked as it starts
        session.check_path(after, path=segment(session.robot, before, after))
    for goal in goals:
        await ctl.moving(job, session.go(goal))


async def actuate(ctl: Controller, job: Job, q: Sequence[float], fraction: float) -> None:
    """The chain to ``q`` [rad or m] at ``fraction`` (0..1) of the joints' limits."""
    session = ctl.session
    speed = session.speed
    session.speed = fraction * 100.0
    try:
        reply = session.go(q)
    finally:
        session.speed = speed
    await ctl.moving(job, reply)


async def halt(ctl: Controller, job: Job) -> None:
    """The arm brakes to rest within its limits; the fingers stop where they are."""
    session = ctl.session
    session.world.grips.stop(session.state, session.source)
    rest = session.world.travels.stop(session.state, session.source)
    await ctl.moving(job, "ok" if rest is None else rest)


async def dwell(ctl: Controller, job: Job, seconds: float) -> None:
    """Wait ``seconds`` [s] of the world's clock."""
    await ctl.session.after(seconds, "ok")


async def grip(ctl: Controller, job: Job, opening: float) -> None:
    """The gripper to ``opening`` (0 closed .. 1 open), as the text verb ``grip``."""
    await ctl.moving(job, ctl.session.execute(Grip(opening)))


async def _at_rest(ctl: Controller, job: Job) -> None:
    """A straight line starts from rest: brake this connection's move under way."""
    session = ctl.session
    if session.travel.active and job.under_way is not None and not job.under_way.over:
        rest = session.world.travels.stop(session.state, session.source)
        if rest is not None:
            await rest
    if session.travel.active:
        raise Refused("a straight move starts from rest, and another door moves the arm now")
