"""What a move is checked against, taken on the event loop: ``world_request``.

A ``planning.MoveRequest`` holds a robot's collision checks as they are now, the
other robots' shapes where they are now (``still_only``: only those standing
still, when the moving ones are checked in time), and the move's start, goals
and settings; the worker's thread checks it while the loop goes on.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..collision.batch import PlacedShape
from ..collision.other_robots import placed_shapes
from ..planning import EdgeResolution, MoveRequest
from ..planning.errors import Cancel
from ..planning.guarded_move import OtherAt
from ..world.world import World

__all__ = ["world_request"]


def world_request(
    world: World,
    robot: str,
    resolution: EdgeResolution,
    start: Sequence[float],
    goals: Sequence[Sequence[float]],
    *,
    path: np.ndarray | None = None,
    target_only: bool = False,
    plan: str = "never",
    timeout_s: float = 1.0,
    seed: int | None = None,
    still_only: bool = False,
    cancel: Cancel | None = None,
) -> MoveRequest:
    """What a move of ``robot`` is checked against now (on the loop): its checks, and the
    other robots where they are (``still_only``: only those standing still); ``cancel``
    stops its plan, if it plans."""
    state = world.state(robot)
    model = world.collision_model(robot)
    shapes: list[PlacedShape] = []
    key: list[OtherAt] = []
    for name, other in world.robots.items():
        moving = world.moving(name)
        if name == robot or (moving and still_only):
            continue
        q = tuple(world.now(name))
        shapes += placed_shapes(name, world.collision_model(name), q, other.origin)
        key.append((name, None if moving else q, other.origin.homogeneous.tobytes()))
    return MoveRequest(
        model,
        model.check_geometry(),
        tuple(shapes),
        tuple(key),
        state.origin,
        resolution,
        tuple(float(x) for x in start),
        tuple(tuple(float(x) for x in goal) for goal in goals),
        path,
        target_only,
        plan,
        timeout_s,
        seed,
        cancel,
    )
