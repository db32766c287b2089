"""Collisions between the robots of a world (a cell): one robot's path against the others.

Each robot's own ``CollisionModel`` checks it against itself and its objects; a
guarded move of one robot of a cell is also checked here against every other
robot as it stands now. Shapes are first compared by their bounding spheres
(numpy, all pairs at once); only pairs whose spheres meet go to coal.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import coal
import numpy as np
import pinocchio as pin

from .model import CollisionModel

__all__ = ["OtherRobot", "first_hit_between"]

OtherRobot = tuple[str, CollisionModel, Sequence[float], pin.SE3]
"""Another robot of the cell as it stands: name, collision model, joints [rad or m], origin."""


def first_hit_between(
    model: CollisionModel,
    origin: pin.SE3,
    others: Sequence[OtherRobot],
    path: Sequence[Sequence[float]],
) -> tuple[int, tuple[str, str]] | None:
    """The first point of a robot's ``path`` at which one of its links meets a link of
    one of the ``others``, and the pair (``link``, ``other_robot/link``); None if none
    does (or there are no others).

    Args:
        model: The moving robot's collision model.
        origin: Where its root stands in the world (cell) frame.
        others: The other robots of the cell as they stand.
        path: The moving robot's chain values along its path [rad or m].
    """
    placed: list[tuple[str, Any, pin.SE3]] = [
        (f"{name}/{link}", geometry, other_origin * placement)
        for name, other_model, q, other_origin in others
        for link, geometry, placement in other_model.link_shapes(q)
    ]
    if not placed:
        return None
    theirs = _spheres(placed)
    for index, q in enumerate(path):
        mine = [
            (link, shape, origin * placement) for link, shape, placement in model.link_shapes(q)
        ]
        ours = _spheres(mine)
        near = np.linalg.norm(ours[0][:, None, :] - theirs[0][None, :, :], axis=2) <= (
            ours[1][:, None] + theirs[1][None, :]
        )
        for i, j in zip(*np.nonzero(near)):
            if _collide(mine[i], placed[j]):
                return index, (mine[i][0], placed[j][0])
    return None


def _spheres(shapes: list[tuple[str, Any, pin.SE3]]) -> tuple[np.ndarray, np.ndarray]:
    """Centres (n, 3) [m] and radii (n,) [m] of bounding spheres of placed shapes."""
    centres, radii = [], []
    for _, geometry, placement in shapes:
        if geometry.aabb_radius <= 0:
            geometry.computeLocalAABB()
        centres.append(placement.act(np.asarray(geometry.aabb_center)))
        radii.append(geometry.aabb_radius)
    return np.array(centres), np.array(radii)


def _collide(a: tuple[str, Any, pin.SE3], b: tuple[str, Any, pin.SE3]) -> bool:
    result = coal.CollisionResult()
    return bool(
        coal.collide(
            a[1],
            coal.Transform3s(a[2].rotation, a[2].translation),
            b[1],
            coal.Transform3s(b[2].rotation, b[2].translation),
            coal.CollisionRequest(),
            result,
        )
    )
