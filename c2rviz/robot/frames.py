"""Frame and rotation conversions, in one place: poses as the language writes them
(x, y, z [m], roll, pitch, yaw [rad]) and as Pinocchio holds them (``pin.SE3``),
unit quaternions as viser and markers hold them (w, x, y, z), and a placement moved
between a robot's base frame and the world frame.

Roll, pitch and yaw are fixed-axis X, then Y, then Z (``R = Rz(yaw) Ry(pitch)
Rx(roll)``), as in URDF and Pinocchio. Pure: numpy and Pinocchio only.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pinocchio as pin

from .rpy import canonical_rpy

__all__ = [
    "in_base",
    "in_world",
    "pose_se3",
    "se3_pose",
    "se3_wxyz",
    "wxyz_rotation",
    "wxyz_se3",
]


def pose_se3(pose: Sequence[float]) -> pin.SE3:
    """``x, y, z, roll, pitch, yaw`` [m, rad] as a placement."""
    x, y, z, roll, pitch, yaw = pose
    return pin.SE3(pin.rpy.rpyToMatrix(roll, pitch, yaw), np.array([x, y, z], dtype=float))


def se3_pose(placement: pin.SE3) -> tuple[float, ...]:
    """A placement as ``x, y, z, roll, pitch, yaw`` [m, rad], the angles in their canonical
    form (``rpy.canonical_rpy``), so a pose sent reads back as sent."""
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
