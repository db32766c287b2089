"""What the camera verbs do: cameras placed, removed, tuned, and what they see."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from ...protocol import replies
from ...protocol.registry import handler
from ...protocol.verbs.cameras import CameraEdit, CamerasQuery
from ...world.camera_sight import seen_text, sight
from ...world.cameras import DEFAULT_FOV_RAD, DEFAULT_RANGE_M, Camera, CameraError

if TYPE_CHECKING:
    from ..session import Session


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
