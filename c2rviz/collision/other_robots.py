"""Collisions between the robots of a world (a cell): one robot's path against the others.

Each robot's own ``CollisionModel`` checks it against itself and its objects; a
guarded move of one robot of a cell is also checked here against every other
robot as it stands now. Shapes are first compared by their bounding spheres
(numpy, all pairs at once); only pairs whose spheres meet go to coal.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import coal
import numpy as np
import pinocchio as pin

if TYPE_CHECKING:
    from ..world.world import World

__all__ = ["first_hit_between"]


def first_hit_between(
    world: World, robot: str, path: Sequence[Sequence[float]]
) -> tuple[int, tuple[str, str]] | None:
    """The first point of ``robot``'s ``path`` at which one of its links meets a link of
    another robot of ``world``, and the pair (``link``, ``other_robot/link``); None if
    none does (or the world has one robot)."""
    state = world.state(robot)
    others: list[tuple[str, Any, pin.SE3]] = []
    for name, other in world.robots.items():
        if name == robot:
            continue
        for link, geometry, placement in world.collision_model(name).link_shapes(other.q):
            others.append((f"{name}/{link}", geometry, other.origin * placement))
    if not others:
        return None
    model = world.collision_model(robot)
    theirs = _spheres(others)
    for index, q in enumerate(path):
        mine = [
            (link, geometry, state.origin * placement)
            for link, geometry, placement in model.link_shapes(q)
        ]
        ours = _spheres(mine)
        near = np.linalg.norm(ours[0][:, None, :] - theirs[0][None, :, :], axis=2) <= (
            ours[1][:, None] + theirs[1][None, :]
        )
        for i, j in zip(*np.nonzero(near)):
            if _collide(mine[i], others[j]):
                return index, (mine[i][0], others[j][0])
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
