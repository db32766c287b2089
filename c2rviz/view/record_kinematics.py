"""The chain's forward kinematics, written out for the recorded page to pose the arm itself.

The recorded page has no server: it poses each link from the recording's joint
values in the browser. Pinocchio stays the one source of truth: ``chain_kinematics``
reads, from the Pinocchio model at ``Robot.home``, each joint's placement in its
parent's frame and, for a joint that a chain value moves (the chain's joints, and
mimic joints through their leader), the twist per unit of that value, found by
moving the value and taking ``log6`` of the change (exact for the revolute and
prismatic joints a chain holds). A joint's placement for chain values ``q`` is
then ``placement * exp6(twist * (q[chain] - home))``, a link's pose its joint's
pose times the link's placement: ``pose_links`` does it in numpy, the page's
player the same in JavaScript, and a test checks both against Pinocchio.

Placements are ``[x, y, z, qw, qx, qy, qz]`` [m].
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import pinocchio as pin

from ..robot.model import Robot, RobotError

__all__ = ["chain_kinematics", "pose_links"]

_DELTA = 0.5  # how far a chain value is moved to read its joints' twists [rad or m]


def _placement(m: pin.SE3) -> list[float]:
    x, y, z, w = pin.Quaternion(m.rotation).coeffs()  # pinocchio: x, y, z, w
    return [*map(float, m.translation), float(w), float(x), float(y), float(z)]


def chain_kinematics(robot: Robot) -> dict[str, Any]:
    """The chain's kinematics as plain numbers (JSON for the page).

    Returns:
        ``joints``: one per Pinocchio joint after the universe, in model order, each
        ``{"parent": index (0: the universe, else 1 + position in this list), "placement",
        "chain": the chain value that moves it (-1: none), "twist": [vx, vy, vz, wx, wy,
        wz] per unit of it, "home": that value at home}``; ``links``: one per link the
        page draws (``Robot.link_names()``), ``{"name", "joint", "placement"}``.

    Raises:
        RobotError: a joint moved by two chain values (no chain the page can draw).
    """
    model = robot.model
    data = model.createData()
    home = list(robot.home)
    pin.forwardKinematics(model, data, robot.configuration(home))
    at_home = [data.liMi[j].copy() for j in range(model.njoints)]
    drivers: dict[int, tuple[int, np.ndarray]] = {}
    for c in range(robot.n):
        q = list(home)
        q[c] += _DELTA
        pin.forwardKinematics(model, data, robot.configuration(q))
        for j in range(1, model.njoints):
            change = at_home[j].actInv(data.liMi[j])
            if change.isIdentity(1e-12):
                continue
            if j in drivers:
                raise RobotError(f"joint {model.names[j]!r} moves with two chain joints")
            drivers[j] = (c, pin.log6(change).vector / _DELTA)
    joints = []
    for j in range(1, model.njoints):
        c, twist = drivers.get(j, (-1, np.zeros(6)))
        joints.append(
            {
                "parent": int(model.parents[j]),
                "placement": _placement(at_home[j]),
                "chain": c,
                "twist": [float(v) for v in twist],
                "home": float(home[c]) if c >= 0 else 0.0,
            }
        )
    links = []
    for link in robot.link_names():
        frame = model.frames[model.getFrameId(link, pin.BODY)]
        joint, where = int(frame.parentJoint), _placement(frame.placement)
        links.append({"name": link, "joint": joint, "placement": where})
    return {"joints": joints, "links": links}


def pose_links(kinematics: dict[str, Any], q: Sequence[float]) -> list[pin.SE3]:
    """Each link's pose in the model's root frame for chain values ``q`` [rad or m], from
    ``chain_kinematics``' numbers alone (what the page computes)."""

    def se3(p: Sequence[float]) -> pin.SE3:
        x, y, z, w, qx, qy, qz = p
        return pin.SE3(pin.Quaternion(w, qx, qy, qz).toRotationMatrix(), np.array([x, y, z]))

    poses = [pin.SE3.Identity()]
    for joint in kinematics["joints"]:
        local = se3(joint["placement"])
        if joint["chain"] >= 0:
            amount = q[joint["chain"]] - joint["home"]
            local = local * pin.exp6(pin.Motion(np.asarray(joint["twist"]) * amount))
        poses.append(poses[joint["parent"]] * local)
    return [poses[link["joint"]] * se3(link["placement"]) for link in kinematics["links"]]
