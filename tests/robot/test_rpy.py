"""canonical_rpy: a pose sent as roll, pitch, yaw reads back as sent, or in its short form."""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from support import examples

from c2rviz.robot.frames import canonical_rpy


def matrix(roll_deg: float, pitch_deg: float, yaw_deg: float) -> np.ndarray:
    return pin.rpy.rpyToMatrix(*np.radians([roll_deg, pitch_deg, yaw_deg]))


def degrees(rpy: tuple[float, float, float]) -> tuple[float, ...]:
    return tuple(round(math.degrees(a), 9) + 0.0 for a in rpy)


def angle_between(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.linalg.norm(pin.log3(a.T @ b)))


READ_BACK = [  # sent (deg) -> what canonical_rpy gives (deg)
    ((0, 90, 0), (0, 90, 0)),
    ((30, 90, 30), (0, 90, 0)),  # gimbal lock: yaw - roll is what counts
    ((10, 90, 40), (0, 90, 30)),
    ((10, -90, 40), (0, -90, 50)),  # at -90: yaw + roll
    ((30.64, 89.99997, 30.64), (0, 90, 0)),  # the reading issue 30 quotes
    ((180, 0, 0), (180, 0, 0)),  # tool down: already the short form
    ((-180, 0, 0), (180, 0, 0)),  # -180 is 180
    ((-179.99999999, 0, 0), (180, 0, 0)),
    ((0, 180, 0), (0, 180, 0)),  # not 180,0,180
    ((0, 150, 0), (0, 150, 0)),  # not 180,30,180
    ((180, 30, 180), (0, 150, 0)),  # the same rotation, shorter
    ((170, 10, 0), (170, 10, 0)),
    ((1e-9, -2e-9, 3e-10), (0, 0, 0)),
    ((12.5, -33.25, 101.75), (12.5, -33.25, 101.75)),
    ((0, 0, -180), (0, 0, 180)),
]


@pytest.mark.parametrize(("sent", "read"), READ_BACK, ids=[str(s) for s, _ in READ_BACK])
def test_reads_back_canonically(sent: tuple[float, ...], read: tuple[float, ...]) -> None:
    rotation = matrix(*sent)
    rpy = canonical_rpy(rotation)
    assert degrees(rpy) == pytest.approx(read, abs=1e-6)
    # the same rotation, to the tolerance
    assert angle_between(pin.rpy.rpyToMatrix(*rpy), rotation) <= 2e-6


def test_pinocchio_reads_the_issue_pose_otherwise() -> None:
    """Why the helper exists: near gimbal lock, matrixToRpy splits the turn anyhow."""
    rotation = matrix(30.64, 89.99997, 30.64)
    plain = np.degrees(pin.rpy.matrixToRpy(rotation))
    assert abs(plain[0]) > 1.0  # not 0,90,0
    assert degrees(canonical_rpy(rotation)) == (0.0, 90.0, 0.0)


def test_a_larger_tolerance_snaps_farther() -> None:
    rotation = matrix(5, 89.99, 5)  # 0.01 deg from the lock
    assert canonical_rpy(rotation)[1] != pytest.approx(math.pi / 2, abs=1e-9)
    roll, pitch, yaw = canonical_rpy(rotation, tolerance_rad=math.radians(0.02))
    assert (roll, pitch) == (0.0, pytest.approx(math.pi / 2))
    assert angle_between(pin.rpy.rpyToMatrix(roll, pitch, yaw), rotation) <= math.radians(0.04)


@settings(max_examples=examples(300), deadline=None)
@given(st.floats(-math.pi, math.pi), st.floats(-math.pi, math.pi), st.floats(-math.pi, math.pi))
@example(2.0, -(1e-6 + 3e-17), 0.5)  # a pitch that snaps to 0 on the second pass (1de4bb0)
def test_any_rotation_round_trips(roll: float, pitch: float, yaw: float) -> None:
    """Any rotation: angles in (-pi, pi], the same rotation back, and no longer than
    either plain triple (matrixToRpy's or its twin)."""
    rotation = pin.rpy.rpyToMatrix(roll, pitch, yaw)
    rpy = canonical_rpy(rotation)
    assert all(-math.pi < a <= math.pi for a in rpy)
    assert angle_between(pin.rpy.rpyToMatrix(*rpy), rotation) <= 3e-6
    plain = pin.rpy.matrixToRpy(rotation)
    assert sum(map(abs, rpy)) <= sum(map(abs, plain)) + 1e-5
    # Again the same, but that an angle a hair over the snap tolerance (1e-6 rad) may come
    # back a hair under it and snap to 0 the second time.
    assert canonical_rpy(pin.rpy.rpyToMatrix(*rpy)) == pytest.approx(rpy, abs=2.5e-6)
