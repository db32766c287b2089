"""Geometry of parts: how far apart two shapes are, how wide a part is along a line,
and how far a released part drops straight down before it meets something.

Shapes are coal geometries placed by ``pin.SE3`` placements in one frame (the world's).
Sizes follow the workcell's: a box's (x, y, z) edges, a cylinder's (radius, length) along
its own z axis, a sphere's (radius,), centred on the placement [m].
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import coal
import numpy as np
import pinocchio as pin

Obstacle = tuple[str, coal.CollisionGeometry, pin.SE3]
"""Something a part may rest on: its name, its shape, its placement in the world."""

_MIN_STEP_M = 0.0005  # a falling part moves down at least this much between two checks
_TOUCH_M = 1e-5  # closer than this is touching


def _transform(placement: pin.SE3) -> coal.Transform3s:
    return coal.Transform3s(placement.rotation, placement.translation)


def signed_distance(
    a: coal.CollisionGeometry, pa: pin.SE3, b: coal.CollisionGeometry, pb: pin.SE3
) -> float:
    """The distance between two placed shapes [m]; negative: how deep they overlap."""
    result = coal.DistanceResult()
    request = coal.DistanceRequest()
    return float(coal.distance(a, _transform(pa), b, _transform(pb), request, result))


def extent(shape: str, size: Sequence[float], rotation: np.ndarray, direction: np.ndarray) -> float:
    """How far the shape reaches from its centre along the unit ``direction`` [m] (half its
    width across that direction), its axes turned by ``rotation``."""
    local = rotation.T @ np.asarray(direction, dtype=float)
    if shape == "box":
        return float(sum(abs(local[i]) * size[i] / 2.0 for i in range(3)))
    if shape == "cylinder":
        radius, length = size
        along = abs(float(local[2]))
        return radius * math.sqrt(max(0.0, 1.0 - along * along)) + length / 2.0 * along
    return float(size[0])


def contains(shape: str, size: Sequence[float], placement: pin.SE3, point: np.ndarray) -> bool:
    """True when ``point`` (same frame as ``placement``) lies inside the shape."""
    local = placement.actInv(np.asarray(point, dtype=float))
    if shape == "box":
        return all(abs(local[i]) <= size[i] / 2.0 + 1e-9 for i in range(3))
    if shape == "cylinder":
        radius, length = size
        return math.hypot(local[0], local[1]) <= radius + 1e-9 and abs(local[2]) <= length / 2.0
    return float(np.linalg.norm(local)) <= size[0] + 1e-9


def drop(
    shape: str,
    size: Sequence[float],
    geometry: coal.CollisionGeometry,
    placement: pin.SE3,
    obstacles: Sequence[Obstacle],
    floor: str = "floor",
) -> tuple[float, str]:
    """How far the part drops straight down before it touches something, and what [m].

    The floor is the plane z = 0. Obstacles the part already overlaps at the start are
    passed by (it was put there). Conservative advancement: the part moves down by its
    distance to the nearest obstacle (at least ``_MIN_STEP_M``), and a step that would
    overlap is halved until it touches.
    """
    bottom = float(placement.translation[2]) - extent(
        shape, size, placement.rotation, np.array([0.0, 0.0, -1.0])
    )
    to_floor = max(bottom, 0.0)
    start = [
        (name, shape_b, where)
        for name, shape_b, where in obstacles
        if signed_distance(geometry, placement, shape_b, where) > -_TOUCH_M
    ]

    def nearest(down: float) -> tuple[float, str]:
        lowered = pin.SE3(placement.rotation, placement.translation - np.array([0, 0, down]))
        best, what = to_floor - down, floor
        for name, shape_b, where in start:
            distance = signed_distance(geometry, lowered, shape_b, where)
            if distance < best:
                best, what = distance, name
        return best, what

    down = 0.0
    gap, what = nearest(down)
    for _ in range(100_000):
        if gap <= _TOUCH_M:
            break
        step = max(gap, _MIN_STEP_M)
        if down + step > to_floor:
            step = to_floor - down
        new_gap, new_what = nearest(down + step)
        while new_gap < -_TOUCH_M and step > _TOUCH_M:  # overlapped: halve the step
            step /= 2.0
            new_gap, new_what = nearest(down + step)
        down += step
        gap, what = new_gap, new_what
        if down >= to_floor:
            return to_floor, floor
    return down, what
