"""What the part verbs do: the gripper's fingers to an opening, travelling as ``motion``
says, by the grasp rule for parts (``Session.grip``, every door's grip); parts added,
removed and asked about, goals and the score."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from ...errors import NoGripper
from ...protocol import replies
from ...protocol.registry import Reply, handler
from ...protocol.verbs.parts import GoalEdit, Grip, PartEdit, PartsQuery, Score
from ...world.goals import DEFAULT_TOL_M, DEFAULT_TOL_RAD, Goal

if TYPE_CHECKING:
    import pinocchio as pin

    from ...world.parts import Part
    from ..session import Session


@handler(Grip)
def grip(session: Session, command: Grip) -> Reply:
    state, grips = session.state, session.world.grips
    if state.robot.gripper is None:
        raise NoGripper(state.name)
    if command.opening is None:
        return replies.ok(replies.numbers([grips.now(state)]))
    return session.grip(command.opening)


def _where(session: Session, part: Part) -> str:
    """The part's pose in the session robot's base frame, in its units."""
    pose: pin.SE3 = session.state.base.inverse() * part.pose
    return session.pose_text(pose)


@handler(PartEdit)
def part(session: Session, command: PartEdit) -> str:
    parts = session.world.parts
    if command.shape == "":
        found = parts.parts.get(command.name)
        return replies.ok(f"{_where(session, found)} {found.state}")
    if command.shape == "remove":
        parts.remove(command.name)
        return replies.OK
    pose = session.state.base * session.pose_se3(command.pose)
    rgba = None if command.rgb is None else (*command.rgb, 1.0)
    parts.add(command.name, command.shape, command.size, pose, command.kind, rgba)
    return replies.OK


@handler(PartsQuery)
def parts(session: Session, command: PartsQuery) -> str:
    every = session.world.parts.parts.all()
    if not every:
        return replies.ok("none")
    return replies.ok(";".join(f"{p.name}:{_where(session, p)}:{p.state}" for p in every))


@handler(GoalEdit)
def goal(session: Session, command: GoalEdit) -> str:
    world_parts = session.world.parts
    if command.remove:
        world_parts.remove_goal(command.key)
        return replies.OK
    angle = session.angle_scale
    tol_m = DEFAULT_TOL_M if command.tol_m is None else command.tol_m
    tol_rad = DEFAULT_TOL_RAD if command.tol_angle is None else command.tol_angle * angle
    pose = session.state.base * session.pose_se3(command.pose)
    world_parts.set_goal(Goal(command.key, pose, tol_m, tol_rad))
    return replies.OK


@handler(Score)
def score(session: Session, command: Score) -> str:
    results = session.world.parts.score()
    if not results:
        return replies.ok("no goals")
    angle = session.angle_scale
    unit = "rad" if math.isclose(angle, 1.0) else "deg"
    met = sum(result.met for result in results)
    notes = [f"{met}/{len(results)} met"]
    for result in results:
        if result.part is None:
            notes.append(f"{result.goal.key} missing")
        elif not result.met:
            held = " (held)" if session.world.parts.parts.get(result.part).holder else ""
            notes.append(
                f"{result.part} {result.off_m * 1000:.1f} mm "
                f"{result.off_rad / angle:.1f} {unit} off{held}"
            )
    return replies.ok("; ".join(notes))
