"""CRCL units to SI, and poses to rotation matrices and back."""

from __future__ import annotations

import math

import numpy as np
import pytest
from crcl_strategies import pose_axes
from hypothesis import given, settings
from hypothesis import strategies as st
from support import examples

from c2rviz.transports.crcl import (
    CrclValueError,
    Point,
    Pose,
    Vector,
    angle_factor,
    force_factor,
    length_factor,
    matrix_to_pose,
    pose_rotation,
    pose_to_matrix,
    torque_factor,
)


@pytest.mark.parametrize(
    ("factor", "unit", "si"),
    [
        (length_factor, "meter", 1.0),
        (length_factor, "millimeter", 0.001),
        (length_factor, "inch", 0.0254),
        (angle_factor, "radian", 1.0),
        (angle_factor, "degree", math.pi / 180),
        (force_factor, "newton", 1.0),
        (force_factor, "pound", 4.4482216152605),
        (force_factor, "ounce", 0.27801385095378125),
        (torque_factor, "newtonMeter", 1.0),
        (torque_factor, "footPound", 1.3558179483314004),
    ],
)
def test_unit_factors(factor: object, unit: str, si: float) -> None:
    assert factor(unit) == pytest.approx(si, rel=1e-15)  # type: ignore[operator]


def test_unknown_unit_names_the_choices() -> None:
    with pytest.raises(
        CrclValueError, match="unknown length unit 'foot' .*meter, millimeter, inch"
    ):
        length_factor("foot")


def test_tool_pointing_down() -> None:
    pose = Pose(Point(500.0, 0.0, 300.0), Vector(1, 0, 0), Vector(0, 0, -1))
    matrix = pose_to_matrix(pose, "millimeter")
    assert np.allclose(matrix[:3, 3], [0.5, 0.0, 0.3])
    assert np.allclose(matrix[:3, :3], [[1, 0, 0], [0, -1, 0], [0, 0, -1]])


def test_axes_of_any_length_are_normalised() -> None:
    rotation = pose_rotation(Pose(Point(0, 0, 0), Vector(0, 5, 0), Vector(0.0, 0.0, 0.25)))
    assert np.allclose(rotation, [[0, -1, 0], [1, 0, 0], [0, 0, 1]])


@settings(max_examples=examples(100), deadline=None)
@given(pose_axes(), st.tuples(*[st.floats(-3, 3)] * 3), st.sampled_from(["meter", "inch"]))
def test_matrix_round_trip(
    axes: tuple[Vector, Vector], xyz: tuple[float, float, float], unit: str
) -> None:
    pose = Pose(Point(*xyz), *axes)
    matrix = pose_to_matrix(pose, unit)
    rotation = matrix[:3, :3]
    assert np.allclose(rotation.T @ rotation, np.eye(3), atol=1e-12)
    assert np.linalg.det(rotation) == pytest.approx(1.0)
    again = matrix_to_pose(matrix, unit)
    assert np.allclose(pose_to_matrix(again, unit), matrix, atol=1e-12)
    assert (again.point.x, again.point.y, again.point.z) == pytest.approx(xyz, abs=1e-12)


@pytest.mark.parametrize(
    ("length_unit", "angle_unit", "expected"),
    [
        ("meter", "radian", [1.0, 1.0, 1.0]),
        ("millimeter", "degree", [math.pi / 180, 0.001, math.pi / 180]),
        ("inch", "radian", [1.0, 0.0254, 1.0]),
    ],
    ids=["si", "mm-deg", "inch-rad"],
)
def test_joint_factors_are_length_for_prismatic_and_angle_for_revolute(
    length_unit: str, angle_unit: str, expected: list[float]
) -> None:
    from c2rviz.transports.crcl.units import joint_factors

    assert joint_factors((False, True, False), length_unit, angle_unit) == expected


def test_crcl_and_the_text_port_convert_through_one_layer() -> None:
    """A revolute joint in degrees scales alike at both doors (``session.units``)."""
    from support import load_robot

    from c2rviz.session.units import UnitTable
    from c2rviz.transports.crcl.units import joint_factors

    robot = load_robot("motoman_sia20d")
    table = UnitTable.build(robot, degrees=True)
    assert list(table.scale) == joint_factors(robot.prismatic, "meter", "degree")
