"""Joint positions and trajectories from ROS clients, checked whole and run on a ``Session``.

A ``sensor_msgs/msg/JointState`` on ``[NS]/joint_command`` is a move like
``move``: the named chain joints go to their positions [rad or m] (the others
keep their target), through ``Session.set_joints`` (the session's motion mode,
speed and guard apply). A ``trajectory_msgs/msg/JointTrajectory`` on
``[NS]/joint_trajectory`` is timed motion: it starts now from where the arm is
(which must be at rest), passes each point at its ``time_from_start`` and is
played on the world's clock (``Session.play_trajectory``); chain joints it does
not name hold still. It is refused whole if any point or any instant between
breaks a position, velocity or acceleration limit (the robot's motion limits at
full speed, whatever the session's ``speed``), or, with ``guard on``, if any
instant of it collides.

The session tells the world of either (``Session.said``: the page's "last
commands", its last error, recordings) as ``/joint_command joint_s=0.5,...`` or
``/joint_trajectory N points, T s``, taken or refused. Units are SI whatever the
session's ``degrees``.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ...errors import ArmMoved, C2rvizError, JointLimitError, within_limit
from ...motion.trajectory import PlannedTrajectory, plan_trajectory
from ...protocol import replies
from ...robot.model import Robot
from ...session.calls import MAX_TRAJECTORY_CHECKS
from ...session.session import Session
from .messages import JointPositions, JointTrajectory

__all__ = ["MAX_GUARD_SAMPLES", "ROWS", "UnknownJointName", "joint_command", "joint_trajectory"]

MAX_GUARD_SAMPLES = MAX_TRAJECTORY_CHECKS
"""Most instants of a trajectory checked for collisions (one per frame, or fewer)."""
ROWS = 500
"""Points' numbers turned into an array in one call at most: numpy holds the interpreter's
lock through it (some 0.3 ms a slice), and the worker thread hands the lock to the event
loop only between calls."""


class UnknownJointName(C2rvizError):
    """A joint name that is not one of the robot's chain joints."""

    def __init__(self, field: str, name: str, robot: Robot, robot_name: str) -> None:
        self.field, self.name = field, name
        shown = name if len(name) <= 60 else name[:60] + "..."
        super().__init__(
            f"{field}: {shown!r} is not a joint of {robot_name}'s chain "
            f"{robot.base} -> {robot.eelink} (its joints: {', '.join(robot.joint_names)})"
        )


def _indices(session: Session, field: str, names: Sequence[str]) -> list[int]:
    index = {name: i for i, name in enumerate(session.robot.joint_names)}
    out = []
    for k, name in enumerate(names):
        if name not in index:
            raise UnknownJointName(f"{field}[{k}]", name, session.robot, session.state.name)
        out.append(index[name])
    return out


def _units(robot: Robot) -> list[str]:
    return ["m" if prismatic else "rad" for prismatic in robot.prismatic]


def joint_command(session: Session, command: JointPositions) -> None:
    """Send the named joints to their positions now (or travelling, as the session moves).

    Raises:
        UnknownJointName: A name that is not a chain joint.
        JointLimitError: A position outside its joint's limits.
        PathCollides: With ``guard on``, the target or the way there collides.
    """
    said = session.said(
        "/joint_command "
        + ",".join(
            f"{name}={replies.numbers([value])}"
            for name, value in zip(command.names, command.positions)
        )
    )
    try:
        robot = session.robot
        q = list(session.state.target)
        units = _units(robot)
        for i, value in zip(_indices(session, "name", command.names), command.positions):
            lower, upper = robot.lower[i], robot.upper[i]
            if not within_limit(value, lower, upper):
                raise JointLimitError(robot.joint_names[i], i, value, lower, upper, units[i])
            q[i] = min(max(value, lower), upper)
    except C2rvizError as error:
        said.refuse(error)
        raise
    session.set_joints(q, said=said)  # motion on: nobody waits for the arrival


async def joint_trajectory(session: Session, trajectory: JointTrajectory) -> None:
    """Check ``trajectory`` whole, then play it from now on the world's clock. Its plan,
    its limit check and (``guard on``) its collision check run off the event loop, on the
    session's worker: a trajectory of thousands of points stalls no other client.

    Raises:
        UnknownJointName: A name that is not a chain joint.
        ArmMoved: The arm is moving (a trajectory starts from rest), or it moved (another
            door drives it) while the trajectory was checked.
        TrajectoryError: A point or an instant between points breaks a limit.
        PathCollides: With ``guard on``, an instant of it collides.
    """
    points = trajectory.points
    said = session.said(
        f"/joint_trajectory {len(points)} points, {points[-1].time_from_start_s:g} s"
    )
    try:
        start, planned = await session.unstopped(_checked(session, trajectory))
        _at_rest(session, start)  # (another door may have moved it meanwhile)
    except C2rvizError as error:
        said.refuse(error)
        raise
    session.play_trajectory(planned, checked=True, said=said)


def _at_rest(session: Session, start: np.ndarray | None = None) -> None:
    """A trajectory starts from rest (at ``start``, where it was planned from)."""
    if session.travel.active or (start is not None and not np.array_equal(session.state.q, start)):
        raise ArmMoved(
            "a trajectory starts from rest and the arm is moving: send stop (or wait) first"
        )


async def _checked(
    session: Session, trajectory: JointTrajectory
) -> tuple[np.ndarray, PlannedTrajectory]:
    """``_plan``, then the guard's check of what it planned."""
    start, planned = await _plan(session, trajectory)
    await session.check_trajectory(planned)
    return start, planned


async def _plan(
    session: Session, trajectory: JointTrajectory
) -> tuple[np.ndarray, PlannedTrajectory]:
    """Where the arm starts, and the trajectory planned and checked against the limits
    from there on the session's worker."""
    indices = _indices(session, "joint_names", trajectory.joint_names)
    _at_rest(session)
    robot, state, world = session.robot, session.state, session.world
    start = np.asarray(state.q, dtype=float)
    zeros = np.zeros(robot.n)
    limits = world.motion_limits(state.name)

    def chain(rows: Sequence[Sequence[float]], base: np.ndarray) -> np.ndarray:
        full = np.tile(base, (len(rows), 1))
        for first in range(0, len(rows), ROWS):  # (the loop may take the lock between)
            full[first : first + ROWS, indices] = rows[first : first + ROWS]
        return full

    def given(rows: list[Sequence[float] | None]) -> list[np.ndarray | None]:
        if rows.count(None) == len(rows):
            return [None] * len(rows)
        present = chain([row for row in rows if row is not None], zeros)
        each = iter(present)
        return [None if row is None else next(each) for row in rows]

    def plan() -> PlannedTrajectory:  # arrays built whole: few Python steps per point
        points = trajectory.points
        return plan_trajectory(
            start,
            [p.time_from_start_s for p in points],
            chain([p.positions for p in points], start),
            given([p.velocities for p in points]),
            given([p.accelerations for p in points]),
            limits,
            robot.joint_names,
            _units(robot),
        )

    return start, await session.services.worker.run(plan, owner=session)
