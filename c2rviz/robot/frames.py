"""Frame and rotation conversions, in one place: poses as the language writes them
(x, y, z [m], roll, pitch, yaw [rad]) and as Pinocchio holds them (``pin.SE3``),
unit quaternions as viser and markers hold them (w, x, y, z), and a placement moved
between a robot's base frame and the world frame.

Roll, pitch and yaw are fixed-axis X, then Y, then Z (``R = Rz(yaw) Ry(pitch)
Rx(roll)``), as in URDF and Pinocchio. Pure: numpy and Pinocchio only.

``canonical_rpy`` gives roll, pitch and yaw of a rotation in one canonical form, so a
pose reads back as sent. Every rotation
has two such triples, ``(r, p, y)`` with ``|p| <= 90 deg`` and
``(r + 180, 180 - p, y + 180)``, and at pitch +-90 deg infinitely many (only
``yaw - roll``, or ``yaw + roll`` at -90 deg, is fixed: gimbal lock). The
canonical form:

- pitch within ``tolerance_rad`` of +-90 deg: pitch exactly +-90, roll 0, and
  yaw carrying the rotation (``moveto ...,0,90,0`` then ``pose`` reads
  ``0,90,0``, not ``30.64,89.99997,30.64``);
- otherwise the shorter of the two triples (the smaller sum of absolute
  angles; the ``|p| <= 90`` one on a tie): ``0,150,0`` reads back as sent,
  not as ``180,30,180``;
- an angle within ``tolerance_rad`` of +-180 deg is +180 deg, and one within
  it of 0 is 0 (no ``-180`` or ``-0.0000001`` for what is 180 or 0).

Every angle [rad], in (-pi, pi].
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import pinocchio as pin


def pose_se3(pose: Sequence[float]) -> pin.SE3:
    """``x, y, z, roll, pitch, yaw`` [m, rad] as a placement."""
    x, y, z, roll, pitch, yaw = pose
    return pin.SE3(pin.rpy.rpyToMatrix(roll, pitch, yaw), np.array([x, y, z], dtype=float))


def se3_pose(placement: pin.SE3) -> tuple[float, ...]:
    """A placement as ``x, y, z, roll, pitch, yaw`` [m, rad], the angles in their canonical
    form (``canonical_rpy``), so a pose sent reads back as sent."""
    return (*map(float, placement.translation), *canonical_rpy(placement.rotation))


def se3_wxyz(placement: pin.SE3) -> tuple[float, float, float, float]:
    """The rotation of a placement as a unit quaternion (w, x, y, z)."""
    x, y, z, w = pin.Quaternion(placement.rotation).coeffs()
    return float(w), float(x), float(y), float(z)


def wxyz_rotation(wxyz: Sequence[float]) -> np.ndarray:
    """A quaternion (w, x, y, z), normalised, as a rotation matrix."""
    w, x, y, z = wxyz
    return pin.Quaternion(w, x, y, z).normalized().toRotationMatrix()


def wxyz_se3(position: Sequence[float], wxyz: Sequence[float]) -> pin.SE3:
    """A position [m] and a quaternion (w, x, y, z) as a placement."""
    return pin.SE3(wxyz_rotation(wxyz), np.array(position, dtype=float))


def in_base(base: pin.SE3, placement_in_world: pin.SE3) -> pin.SE3:
    """A world-frame placement in the frame ``base`` (a robot's base in the world)."""
    return base.actInv(placement_in_world)


def in_world(base: pin.SE3, placement_in_base: pin.SE3) -> pin.SE3:
    """A placement in the frame ``base`` (a robot's base in the world) in the world frame."""
    return base * placement_in_base


def canonical_rpy(rotation: np.ndarray, tolerance_rad: float = 1e-6) -> tuple[float, float, float]:
    """The canonical (roll, pitch, yaw) [rad] of a rotation matrix.

    Args:
        rotation: A 3x3 rotation matrix.
        tolerance_rad: How near +-90 deg of pitch counts as gimbal lock, and
            how near 0 or 180 deg an angle snaps there [rad]. The triple
            returned turns the frame at most about this much from ``rotation``.

    Returns:
        (roll, pitch, yaw) [rad], each in (-pi, pi], with
        ``rotation ~= Rz(yaw) @ Ry(pitch) @ Rx(roll)``.
    """
    r = np.asarray(rotation, dtype=float)
    sin_pitch = -float(r[2, 0])
    cos_pitch = math.hypot(float(r[0, 0]), float(r[1, 0]))
    pitch = math.atan2(sin_pitch, cos_pitch)  # in [-pi/2, pi/2]
    if math.pi / 2 - abs(pitch) <= tolerance_rad:
        # Gimbal lock: only yaw - roll (+90) or yaw + roll (-90) is fixed; give it to yaw.
        yaw = math.atan2(-float(r[0, 1]), float(r[1, 1]))
        return 0.0, math.copysign(math.pi / 2, sin_pitch), _snap(yaw, tolerance_rad)
    roll = math.atan2(float(r[2, 1]), float(r[2, 2]))
    yaw = math.atan2(float(r[1, 0]), float(r[0, 0]))
    near = tuple(_snap(a, tolerance_rad) for a in (roll, pitch, yaw))
    far = tuple(_snap(a, tolerance_rad) for a in (roll + math.pi, math.pi - pitch, yaw + math.pi))
    if sum(map(abs, far)) < sum(map(abs, near)) - tolerance_rad:
        return far[0], far[1], far[2]
    return near[0], near[1], near[2]


def _snap(angle: float, tolerance: float) -> float:
    """``angle`` in (-pi, pi]; within ``tolerance`` of 0 it is 0, of +-pi it is pi."""
    wrapped = math.remainder(angle, math.tau)  # in [-pi, pi]
    if abs(wrapped) <= tolerance:
        return 0.0
    if math.pi - abs(wrapped) <= tolerance:
        return math.pi
    return wrapped
