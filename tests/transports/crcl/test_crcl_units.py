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


def test_a_move_throughs_waypoints_become_placements_one_by_one(monkeypatch) -> None:
    """A ``MoveThroughTo``'s waypoints become placements as each leg asks for its own, none
    up front (a thousand at once held the event loop some 30 ms); a placement is
    ``pose_to_matrix``'s, and every point is checked at once: one out of range refuses
    them all before any is made."""
    from c2rviz.transports.crcl import motions

    made: list[Pose] = []
    real = motions.placement
    monkeypatch.setattr(motions, "placement", lambda p, unit: (made.append(p), real(p, unit))[1])
    down = (Vector(1.0, 0.0, 0.0), Vector(0.0, 0.0, -1.0))
    poses = [Pose(Point(500.0, 10.0 * k, 800.0), *down) for k in range(4)]
    targets = motions.Placements(poses, "millimeter")
    assert len(targets) == 4 and made == []
    assert np.array_equal(targets[2].homogeneous, pose_to_matrix(poses[2], "millimeter"))
    assert made == [poses[2]]
    assert [t.translation[1] for t in targets[1:3]] == pytest.approx([0.01, 0.02])
    assert [t.translation[1] for t in targets] == pytest.approx([0.0, 0.01, 0.02, 0.03])
    far = [*poses, Pose(Point(500.0, 2e3, 800.0), *down), Pose(Point(3e3, 0.0, 0.0), *down)]
    made.clear()
    with pytest.raises(CrclValueError, match=r"^Point/Y: 2000 meter is out of range"):
        motions.Placements(far, "meter")
    assert made == []
