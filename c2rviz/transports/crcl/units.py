"""CRCL's unit names, and CRCL poses to rotation matrices and back (numpy only).

CRCL documents carry values in the units their connection has set; c2rviz computes
in SI (meters, radians, newtons, newton-meters). Each factor here is how many SI units
one CRCL unit is: ``value_si = value * LENGTH_FACTORS[unit]``, its size taken from the
session's conversion layer (``session.units``), which the text port's degrees use too.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import Final

import numpy as np
from numpy.typing import NDArray

from ...protocol.grammar import POSITION_M
from ...session.units import DEGREE_RAD, FOOT_M, INCH_M, MILLIMETER_M, POUND_FORCE_N, joint_scale
from .errors import CrclValueError
from .primitives import Point, Pose, Vector

LENGTH_FACTORS: Final[Mapping[str, float]] = {
    "meter": 1.0,
    "millimeter": MILLIMETER_M,
    "inch": INCH_M,
}
"""Meters per CRCL length unit."""

ANGLE_FACTORS: Final[Mapping[str, float]] = {"radian": 1.0, "degree": DEGREE_RAD}
"""Radians per CRCL angle unit."""

FORCE_FACTORS: Final[Mapping[str, float]] = {
    "newton": 1.0,
    "pound": POUND_FORCE_N,  # pound-force
    "ounce": POUND_FORCE_N / 16.0,
}
"""Newtons per CRCL force unit."""

TORQUE_FACTORS: Final[Mapping[str, float]] = {
    "newtonMeter": 1.0,
    "footPound": POUND_FORCE_N * FOOT_M,
}
"""Newton-meters per CRCL torque unit."""


def _factor(table: Mapping[str, float], unit: str, what: str) -> float:
    factor = table.get(unit)
    if factor is None:
        raise CrclValueError(f"unknown {what} unit {unit!r} (choose from: {', '.join(table)})")
    return factor


def length_factor(unit: str) -> float:
    """Meters per ``unit`` (``meter``, ``millimeter`` or ``inch``)."""
    return _factor(LENGTH_FACTORS, unit, "length")


def angle_factor(unit: str) -> float:
    """Radians per ``unit`` (``radian`` or ``degree``)."""
    return _factor(ANGLE_FACTORS, unit, "angle")


def force_factor(unit: str) -> float:
    """Newtons per ``unit`` (``newton``, ``pound`` or ``ounce``)."""
    return _factor(FORCE_FACTORS, unit, "force")


def torque_factor(unit: str) -> float:
    """Newton-meters per ``unit`` (``newtonMeter`` or ``footPound``)."""
    return _factor(TORQUE_FACTORS, unit, "torque")


def joint_factors(prismatic: tuple[bool, ...], length_unit: str, angle_unit: str) -> list[float]:
    """SI per CRCL unit for each joint (``length_unit`` for a prismatic joint, ``angle_unit``
    for a revolute one), through the session's ``joint_scale``."""
    return list(joint_scale(prismatic, angle_factor(angle_unit), length_factor(length_unit)))


def pose_rotation(pose: Pose) -> NDArray[np.float64]:
    """The rotation matrix of a pose's tool frame in the base frame.

    Its columns are the x, y and z axes: z is ``ZAxis`` normalised, x is ``XAxis`` made
    exactly orthogonal to z (Gram-Schmidt; a ``Pose`` is only ever a hair off) and
    normalised, y is z cross x.
    """
    z = np.array([pose.z_axis.i, pose.z_axis.j, pose.z_axis.k], dtype=float)
    z /= np.linalg.norm(z)
    x = np.array([pose.x_axis.i, pose.x_axis.j, pose.x_axis.k], dtype=float)
    x -= np.dot(x, z) * z
    x /= np.linalg.norm(x)
    return np.column_stack((x, np.cross(z, x), z))


def check_points(points: Iterable[Point], length_unit: str = "meter") -> None:
    """Refuse the first coordinate of ``points`` (in ``length_unit``) farther than
    ``protocol.grammar.POSITION_M`` (1000 m) from the origin, as the text port refuses it.

    Raises:
        CrclValueError: naming the coordinate (``Point X``).
    """
    factor = length_factor(length_unit)
    for point in points:
        for label, value in zip("XYZ", (point.x, point.y, point.z)):
            if abs(value * factor) > POSITION_M:
                raise (
                    CrclValueError(
                        f"{value:g} {length_unit} is out of range: a position lies within "
                        f"-{POSITION_M:g}..{POSITION_M:g} m of the origin"
                    )
                    .within(label)
                    .within("Point")
                )


def pose_to_matrix(pose: Pose, length_unit: str = "meter") -> NDArray[np.float64]:
    """The 4x4 homogeneous transform of a pose, its translation in meters.

    Args:
        pose: A pose in ``length_unit``.
        length_unit: The unit its point is in.

    Raises:
        CrclValueError: A coordinate farther than ``protocol.grammar.POSITION_M``
            (1000 m) from the origin, as the text port refuses it.
    """
    factor = length_factor(length_unit)
    check_points((pose.point,), length_unit)
    point = pose.point
    matrix = np.eye(4)
    matrix[:3, :3] = pose_rotation(pose)
    matrix[:3, 3] = (point.x * factor, point.y * factor, point.z * factor)
    return matrix


def matrix_to_pose(matrix: NDArray[np.float64], length_unit: str = "meter") -> Pose:
    """The CRCL pose of a homogeneous transform (translation in meters), in ``length_unit``.

    Raises:
        CrclValueError: The matrix's rotation columns are not orthogonal directions.
    """
    factor = length_factor(length_unit)
    x, y, z = (float(value) / factor for value in matrix[:3, 3])
    rotation = matrix[:3, :3]
    return Pose(
        Point(x, y, z),
        Vector(*(float(value) for value in rotation[:, 0])),
        Vector(*(float(value) for value in rotation[:, 2])),
    )
