"""What the part verbs do: the gripper's fingers to an opening, travelling as ``motion``
says, by the grasp rule for parts (``Session.grip``, every door's grip); parts added,
removed and asked about, goals and the score; and what the camera verbs do: cameras
placed, removed, tuned, and the parts they see.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from ...errors import NoGripper
from ...protocol import replies
from ...protocol.registry import Reply, handler
from ...protocol.verbs.parts import (
    CameraEdit,
    CamerasQuery,
    GoalEdit,
    Grip,
    PartEdit,
    PartsQuery,
    Score,
)
from ...world.cameras import DEFAULT_FOV_RAD, DEFAULT_RANGE_M, Camera, CameraError
from ...world.part_rules import DEFAULT_TOL_M, DEFAULT_TOL_RAD, Goal
from ...world.world import seen_text, sight

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


@handler(CameraEdit)
def camera(session: Session, command: CameraEdit) -> str:
    cameras = session.world.cameras
    angle = session.angle_scale
    if command.action == "look":
        return replies.ok(seen_text(sight(session.world, command.name), angle))
    if command.action == "remove":
        cameras.remove(command.name)
        return replies.OK
    if command.action == "rate":
        cameras.get(command.name).rate_hz = command.values[0]
        cameras.changed()
        return replies.OK
    if command.action == "noise":
        found = cameras.get(command.name)
        sigma_m, sigma_angle = command.values
        sigma_rad = sigma_angle * angle
        if sigma_rad > math.pi:
            raise CameraError(f"angle noise {sigma_angle:g} is above half a turn")
        found.sigma_m, found.sigma_rad = sigma_m, sigma_rad
        # Each noise setting draws its own generator from the program's (--seed): a run
        # with the same seed and the same lines reports the same noisy poses.
        found.rng = np.random.default_rng(int(session.services.rng.integers(0, 2**63)))
        cameras.changed()
        return replies.OK
    h_fov, v_fov, range_m = (*DEFAULT_FOV_RAD, DEFAULT_RANGE_M)
    if command.view is not None:
        h_fov, v_fov = command.view[0] * angle, command.view[1] * angle
        range_m = command.view[2]
    new = Camera(command.name, session.pose_se3(command.pose), h_fov, v_fov, range_m)
    if command.name in cameras:  # moved: it keeps its rate, noise and blackout
        old = cameras.get(command.name)
        new.rate_hz, new.sigma_m, new.sigma_rad = old.rate_hz, old.sigma_m, old.sigma_rad
        new.rng, new.blackout_until = old.rng, old.blackout_until
    cameras.put(new)
    return replies.OK


@handler(CamerasQuery)
def cameras(session: Session, command: CamerasQuery) -> str:
    every = session.world.cameras.all()
    if not every:
        return replies.ok("none")
    angle = session.angle_scale
    items = []
    for one in every:
        view = replies.numbers([one.h_fov_rad / angle, one.v_fov_rad / angle, one.range_m])
        items.append(
            f"{one.name}:{session.pose_text(one.pose)}:{view}:{replies.numbers([one.rate_hz])}"
        )
    return replies.ok(";".join(items))
