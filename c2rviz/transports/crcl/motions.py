"""The CRCL commands that take time, as jobs of a ``Controller`` on its session.

Each job plans first (nothing moves while it does, so a refusal moves nothing),
then starts its motion through ``Controller.moving`` (which starts none for a job
taken over meanwhile) and waits for the session's reply on arrival. Every move is a
typed call of the session (``plan_to``, ``play``, ``set_joints``, ``stop``, ``grip``,
``dwell``), the same planning and playing the text port's ``moveto`` and ``movel``
use: the session's speed, ``lspeed``, guard (on for CRCL) and the world's limits and
collisions apply alike.

- ``MoveTo``: through joint space (``moveto``) or, ``MoveStraight``, along the tool's
  straight line (``movel``), which starts from rest: a move of this connection under
  way is braked first.
- ``MoveThroughTo``: every waypoint solved (or every line planned) and checked, off the
  event loop, before the arm moves, then one after the other; an error names the
  waypoint (1-based). Each waypoint becomes a placement as its leg is planned
  (``Placements``), so a thousand of them never hold the loop at once.
- ``ActuateJoints``: the named joints (the others keep their target) at the speed
  their ``JointSpeed``/``JointAccel`` allow within the limits.
- ``StopMotion``/``EndCanon``: the arm brakes within its limits, the fingers stop.
- ``Dwell``: a pause on the world's clock. ``SetEndEffector``: the gripper's ``grip``.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from typing import overload

import pinocchio as pin

from ...ik.chain import Target
from .controller import Controller, Job, Refused
from .primitives import Pose
from .units import check_points, pose_to_matrix


def placement(pose: Pose, length_unit: str) -> pin.SE3:
    """A CRCL pose (in ``length_unit``) as a placement in the base frame [m]."""
    return pin.SE3(pose_to_matrix(pose, length_unit))


class Placements(Sequence[pin.SE3]):
    """CRCL poses (in ``length_unit``) as placements in the base frame [m], each made as it
    is asked for: a ``MoveThroughTo``'s waypoint as its leg is planned, in that leg's turn
    of the event loop (a thousand made at once held it some 30 ms). Their points are
    checked whole when it is made, so a waypoint out of range refuses the command at once.

    Raises:
        CrclValueError: A point out of range (``units.check_points``).
    """

    def __init__(self, poses: Sequence[Pose], length_unit: str) -> None:
        check_points((pose.point for pose in poses), length_unit)
        self.poses, self.length_unit = poses, length_unit

    def __len__(self) -> int:
        return len(self.poses)

    @overload
    def __getitem__(self, index: int) -> pin.SE3: ...

    @overload
    def __getitem__(self, index: slice) -> list[pin.SE3]: ...

    def __getitem__(self, index: int | slice) -> pin.SE3 | list[pin.SE3]:
        if isinstance(index, slice):
            return [placement(pose, self.length_unit) for pose in self.poses[index]]
        return placement(self.poses[index], self.length_unit)


async def move_to(ctl: Controller, job: Job, target: pin.SE3, straight: bool) -> None:
    """The tool point to ``target``: along a straight line, or through joint space."""
    session = ctl.session
    if straight:
        await _at_rest(ctl, job)
    plan = await session.plan_to(target, straight=straight)
    await ctl.moving(job, lambda: session.play(plan))


async def move_through(
    ctl: Controller, job: Job, targets: Sequence[Target], straight: bool
) -> None:
    """Through every target in turn, all of them planned and checked (off the event loop)
    before any move; an error names the waypoint (1-based)."""
    session = ctl.session
    if straight:
        await _at_rest(ctl, job)
    for plan in await session.plan_through(targets, straight=straight):
        await ctl.moving(job, functools.partial(session.play, plan))


async def actuate(ctl: Controller, job: Job, q: Sequence[float], fraction: float) -> None:
    """The chain to ``q`` [rad or m] at ``fraction`` (0..1) of the joints' limits."""
    session = ctl.session
    await ctl.moving(job, lambda: session.set_joints(q, speed=fraction * 100.0))


async def halt(ctl: Controller, job: Job) -> None:
    """The arm brakes to rest within its limits; the fingers stop where they are."""
    session = ctl.session
    await ctl.moving(job, lambda: session.stop(fingers=True))


async def dwell(ctl: Controller, job: Job, seconds: float) -> None:
    """Wait ``seconds`` [s] of the world's clock."""
    reply = ctl.session.dwell(seconds)
    if not isinstance(reply, str):
        await reply


async def grip(ctl: Controller, job: Job, opening: float) -> None:
    """The gripper to ``opening`` (0 closed .. 1 open), as the text verb ``grip``."""
    session = ctl.session
    await ctl.moving(job, lambda: session.grip(opening))


async def _at_rest(ctl: Controller, job: Job) -> None:
    """A straight line starts from rest: brake this connection's move under way."""
    session = ctl.session
    if session.travel.active and job.under_way is not None and not job.under_way.over:
        rest = session.stop()
        if not isinstance(rest, str):
            await rest
    if session.travel.active:
        raise Refused("a straight move starts from rest, and another door moves the arm now")
