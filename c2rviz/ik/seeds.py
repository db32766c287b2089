"""Where restarts begin: stored configurations, ranked by how close their tool pose is.

At construction the solver draws a fixed set of random in-limit
configurations (a seeded rng: the same set every time) and stores the
placement of the end-effector joint for each. For a goal, the tool pose of
every one follows in a few vectorised numpy operations (the tool offset is
applied then, so it may change between calls), and the restarts begin from
the closest, in order: a restart from a configuration whose tool is already
near the goal lands in a solution's basin far more often than one from a
random configuration (on the bundled arms the 99th percentile of steps per
solve falls from about 150 to about 60).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from .chain import IkChain
from .target import Goal

__all__ = ["SeedPool"]


class SeedPool:
    """Random in-limit configurations with their end-effector joint placements.

    Args:
        chain: The chain (its model; the tool frame's offset is read per call).
        count: How many configurations to store.
        seed: Seed of the rng that draws them.
        orientation_cost: Weight of 1 rad against 1 m when ranking [m/rad].
    """

    def __init__(self, chain: IkChain, count: int, seed: int, orientation_cost: float) -> None:
        self.chain = chain
        self.weight = orientation_cost
        model = chain.model
        data = model.createData()
        rng = np.random.default_rng(seed)
        joint = model.frames[chain.tool_frame].parentJoint
        self.configurations: list[np.ndarray] = []
        self._positions = np.empty((count, 3))
        self._rotations = np.empty((count, 3, 3))
        for i in range(count):
            q = chain.to_model(chain.robot.random(rng))
            pin.forwardKinematics(model, data, q)
            self.configurations.append(q)
            self._positions[i] = data.oMi[joint].translation
            self._rotations[i] = data.oMi[joint].rotation

    def ranked(self, goal: Goal, count: int) -> list[np.ndarray]:
        """The ``count`` stored configurations whose tool is closest to ``goal``, closest first.

        Closeness is ``hypot(distance, orientation_cost * angle)``, the cost the
        descents minimise (the distance alone for a point goal); ties keep the
        stored order, so the ranking is repeatable.
        """
        frame = self.chain.model.frames[self.chain.tool_frame].placement
        positions = self._positions + self._rotations @ frame.translation
        cost = np.sum((positions - goal.position) ** 2, axis=1)
        if goal.rotation is not None:
            # trace(goal^T R_joint R_frame) = 1 + 2 cos(angle)
            turn = frame.rotation @ goal.rotation.T
            cosine = (np.einsum("ij,nji->n", turn, self._rotations) - 1.0) / 2.0
            angle = np.arccos(np.clip(cosine, -1.0, 1.0))
            cost += (self.weight * angle) ** 2
        count = min(count, len(self.configurations))
        if count <= 0:
            return []
        best = np.argpartition(cost, count - 1)[:count]
        order = best[np.lexsort((best, cost[best]))]
        return [self.configurations[i] for i in order]
