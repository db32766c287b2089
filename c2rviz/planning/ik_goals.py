"""Several IK solutions of one tool pose, for a planner to choose the one it can reach.

A redundant arm, or one with elbow and wrist flips, puts its tool at a pose in
several ways; the one nearest the arm may sit behind an obstacle while another
is free and reachable. ``goal_candidates`` gives the solver's own answer (the one
``ik`` and ``moveto`` use) first, then distinct answers from the solver's
restarts (its stored seed configurations closest to the target), nearest the
arm first. Use it on the solver's thread.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pinocchio as pin

from c2rviz.ik import IkSolver, Target
from c2rviz.ik.chain import goal_in_world

__all__ = ["DISTINCT_RAD", "goal_candidates"]

DISTINCT_RAD = 1e-3  # [rad or m] answers closer than this on every joint are one answer


def goal_candidates(
    solver: IkSolver,
    target: Target,
    near: Sequence[float],
    tool: pin.SE3 | None = None,
    count: int = 6,
) -> list[tuple[float, ...]]:
    """Up to ``count`` distinct chain values [rad or m] that put the tool at ``target``.

    Args:
        solver: The robot's IK solver.
        target: Tool pose in the base frame, or a point (``ik.PointTarget``).
        near: The arm's chain values now [rad or m].
        tool: Tool offset from the end-effector link.
        count: Most answers returned.

    Raises:
        Unreachable: the solver's own answer fails (beyond reach, or no attempt got there).
    """
    first = solver.solve(target, near, tool)
    found = [np.array(first)]
    settings = solver.settings
    solver.chain.set_tool(tool)
    goal = goal_in_world(target, solver.chain.base_placement)
    for start in solver.seeds.ranked(goal, settings.max_attempts):
        if len(found) >= count:
            break
        descent = solver.newton.descend(start, goal, settings.max_iterations)
        if not descent.ok:
            continue
        q = np.array(solver.chain.to_chain(descent.q, near))
        if all(np.max(np.abs(q - other)) > DISTINCT_RAD for other in found):
            found.append(q)
    rest = sorted(found[1:], key=lambda q: float(np.linalg.norm(q - np.asarray(near))))
    return [tuple(float(x) for x in q) for q in (found[0], *rest)]
