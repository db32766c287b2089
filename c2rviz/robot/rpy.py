"""Roll, pitch and yaw of a rotation in one canonical form, so a pose reads back as sent.

``R = Rz(yaw) Ry(pitch) Rx(roll)`` (URDF and ``pin.rpy`` order). Every rotation
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

Pure numpy; every angle [rad], in (-pi, pi].
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["canonical_rpy"]


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
