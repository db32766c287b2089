"""Collisions between the robots of a world (a cell): one robot against the others.

Each robot's own ``CollisionModel`` checks it against itself and its objects;
here a robot is checked against every other robot as it stands:
``pairs_between`` (every touching pair now, for ``collisions``) and
``first_hit_between`` (the first point of a path that touches). Shapes are
first compared by their bounding spheres (numpy, all pairs at once); only pairs
whose spheres meet go to coal. ``placed_shapes`` places a robot's shapes in the
cell (for a ``BatchCheck`` that holds other robots as fixed obstacles).

A pair between robots is ``(link, other/link)``: this robot's link, then the
other robot's name and link (``collisions`` writes ``link_t~right/link_4``).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import coal
import numpy as np
import pinocchio as pin

from .batch import PlacedShape, may_touch
from .geometry import Pair
from .model import CollisionModel

OtherRobot = tuple[str, CollisionModel, Sequence[float], pin.SE3]
"""Another robot of the cell as it stands: name, collision model, joints [rad or m], origin."""


def placed_shapes(
    name: str, collision: CollisionModel, q: Sequence[float], origin: pin.SE3
) -> list[PlacedShape]:
    """Every collision shape of the robot ``name`` at ``q`` [rad or m], placed in the cell.

    Args:
        name: The robot's name in the cell; each shape is named ``name/link``.
        collision: Its collision model.
        q: Its chain values [rad or m].
        origin: Placement of its model's root frame in the cell [m].
    """
    return [
        (f"{name}/{link}", geometry, origin * placement)
        for link, geometry, placement in collision.link_shapes(q)
    ]


def pairs_between(
    model: CollisionModel, origin: pin.SE3, q: Sequence[float], others: Sequence[OtherRobot]
) -> list[Pair]:
    """Every pair (``link``, ``other/link``) in contact between a robot at ``q`` [rad or m]
    (its root at ``origin``) and the ``others`` as they stand, sorted."""
    placed = [shape for name, m, oq, o in others for shape in placed_shapes(name, m, oq, o)]
    if not placed:
        return []
    mine = [(link, shape, origin * placement) for link, shape, placement in model.link_shapes(q)]
    near = _apart(model, mine, placed, _near(mine, placed))
    return sorted({(mine[i][0], placed[j][0]) for i, j in near if _collide(mine[i], placed[j])})


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
    placed = [shape for name, m, oq, o in others for shape in placed_shapes(name, m, oq, o)]
    if not placed:
        return None
    for index, q in enumerate(path):
        mine = [
            (link, shape, origin * placement) for link, shape, placement in model.link_shapes(q)
        ]
        for i, j in _apart(model, mine, placed, _near(mine, placed)):
            if _collide(mine[i], placed[j]):
                return index, (mine[i][0], placed[j][0])
    return None


def _apart(
    model: CollisionModel,
    mine: list[tuple[str, Any, pin.SE3]],
    theirs: list[tuple[str, Any, pin.SE3]],
    pairs: list[tuple[int, int]],
) -> list[tuple[int, int]]:
    """``pairs`` less a finger and a held part, which may touch (``batch.may_touch``)."""
    source = model.check_geometry()
    if not source.parts:
        return pairs
    return [(i, j) for i, j in pairs if not may_touch(source, mine[i][0], theirs[j][0])]


def _near(
    mine: list[tuple[str, Any, pin.SE3]], theirs: list[tuple[str, Any, pin.SE3]]
) -> list[tuple[int, int]]:
    """The index pairs of shapes whose bounding spheres meet."""
    ours, others = _spheres(mine), _spheres(theirs)
    near = np.linalg.norm(ours[0][:, None, :] - others[0][None, :, :], axis=2) <= (
        ours[1][:, None] + others[1][None, :]
    )
    return [(int(i), int(j)) for i, j in zip(*np.nonzero(near))]


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
