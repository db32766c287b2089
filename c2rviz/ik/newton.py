"""Damped Newton descents of the tool frame: the IK's fast path, in numpy over Pinocchio.

One step: Pinocchio's frame Jacobian and placement (one call, forward
kinematics included), the error as position difference [m] and rotation vector
[rad] in world axes (weighted by ``orientation_cost``), and the damped
least-squares step ``J^T (J J^T + lambda^2 I)^-1 e`` (or its n x n twin when the
chain has fewer joints than the error has rows). ``lambda^2`` grows with the
error (Levenberg-Marquardt): long cautious steps far away, full Newton steps
near the target, where the error falls quadratically. The minimum-norm step
keeps a redundant arm near where it starts.

Joint limits: a joint whose step would cross its limit stops on it, and the
others are solved again without it (one active-set pass), so an arm pressed on
a stop still slides along it. Pure: no clock, no I/O, no randomness.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from typing import Any, NamedTuple

import numpy as np
import pinocchio as pin

from .chain import Goal, IkChain

# A descent stalls when its cost is not ``stall_ratio`` of 3 steps before (after 5 steps).
_STALL_AFTER, _STALL_LAG = 5, 3
_EXACT = 1e-13  # a converged descent takes more steps while its cost is above this [m] ...
_POLISH_STEPS = 3  # ... up to this many
_WORLD = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
_IDENTITY = [np.eye(n) for n in range(7)]  # the damping's identity, by size (at most 6 rows)


class Descent(NamedTuple):
    """The end of one descent.

    Attributes:
        ok: True when the tool is within tolerance of the goal.
        q: The model's configuration reached.
        distance_m: Tool position error [m].
        angle_rad: Tool orientation error [rad] (0 when the orientation is free).
        iterations: Steps taken.
    """

    ok: bool
    q: np.ndarray
    distance_m: float
    angle_rad: float
    iterations: int


class NewtonDescent:
    """Damped Newton descents on one chain's model. Not thread-safe (one pin.Data).

    Args:
        chain: The chain (its model and tool frame; ``set_tool`` is seen at once).
        orientation_cost: Weight of 1 rad against 1 m of error [m/rad].
        position_tolerance_m: Position error that counts as there [m].
        angle_tolerance_rad: Orientation error that counts as there [rad].
        max_step: Largest change of any joint in one step [rad or m].
        damping: Levenberg-Marquardt factor: ``lambda^2 = 1e-9 + damping * cost^2`` [1/m^2].
    """

    def __init__(
        self,
        chain: IkChain,
        orientation_cost: float,
        position_tolerance_m: float,
        angle_tolerance_rad: float,
        max_step: float,
        damping: float,
    ) -> None:
        self.chain = chain
        self.model = model = chain.model
        self.data = model.createData()
        self.frame = chain.tool_frame
        self.weight = orientation_cost
        self.position_tolerance_m = position_tolerance_m
        self.angle_tolerance_rad = angle_tolerance_rad
        self.max_step = max_step
        self.damping = damping
        self.steps = 0  # every step taken since construction (for tests and benchmarks)
        # Velocity-space view of the limits: a (cos, sin) joint is unbounded.
        self._simple = model.nq == model.nv
        q_of_v = np.zeros(model.nv, dtype=int)
        bounded = np.zeros(model.nv, dtype=bool)
        for joint in model.joints[1:]:
            for k in range(joint.nv):
                q_of_v[joint.idx_v + k] = joint.idx_q + k
                bounded[joint.idx_v + k] = joint.nq == joint.nv
        self._q_of_v = q_of_v
        self._v_lower = np.where(bounded, chain.lower[q_of_v], -np.inf)
        self._v_upper = np.where(bounded, chain.upper[q_of_v], np.inf)

    def descend(
        self,
        q0: np.ndarray,
        goal: Goal,
        iterations: int,
        *,
        limited: bool = True,
        stall_ratio: float = 0.9,
        exact: bool = True,
    ) -> Descent:
        """Up to ``iterations`` steps from ``q0`` towards ``goal``; fewer when done or stalled.

        Args:
            q0: The model's configuration to start from (within the limits when ``limited``).
            goal: The target in the model's world frame.
            iterations: Most steps taken.
            limited: Keep the joints within their limits (else the model's limits are ignored).
            stall_ratio: Give up when the cost is not this fraction of 3 steps before.
            exact: Once within tolerance, take up to 3 more steps while each halves
                the error: it falls quadratically, so the answer is then exact to
                rounding (a pose sent reads back as sent).
        """
        model, data, frame = self.model, self.data, self.frame
        target_p, target_r = goal.position, goal.rotation
        weight = self.weight
        tol_p, tol_a = self.position_tolerance_m, self.angle_tolerance_rad
        jacobian_of, log3, sqrt, hypot = pin.computeFrameJacobian, pin.log3, math.sqrt, math.hypot
        error = np.empty(3 if target_r is None else 6)
        q = q0
        costs: list[float] = []
        best: Descent | None = None  # converged: kept while a few more steps polish it
        polish = 0
        distance = angle = math.inf
        step = 0
        for step in range(iterations + 2 + _POLISH_STEPS):  # noqa: B007 (read after the loop)
            jacobian = jacobian_of(model, data, q, frame, _WORLD)
            placement = data.oMf[frame]
            error[:3] = target_p - placement.translation
            if target_r is None:
                jacobian = jacobian[:3]
                x, y, z = error.tolist()
                distance, angle = sqrt(x * x + y * y + z * z), 0.0
            else:
                error[3:] = log3(target_r @ placement.rotation.T)
                x, y, z, rx, ry, rz = error.tolist()
                distance, angle = sqrt(x * x + y * y + z * z), sqrt(rx * rx + ry * ry + rz * rz)
                error[3:] *= weight
                jacobian[3:] *= weight
            cost = hypot(distance, weight * angle)
            within = distance <= tol_p and angle <= tol_a
            if best is not None:  # polishing: keep a step only while it halves the cost
                if not within or cost > 0.5 * costs[-1]:
                    return best
                best = Descent(True, q, distance, angle, step)
                if cost <= _EXACT or polish >= _POLISH_STEPS:
                    return best
                polish += 1
            elif within:
                best = Descent(True, q, distance, angle, step)
                if not exact or cost <= _EXACT:
                    return best
                polish = 1  # quadratic convergence: a step or two more read back exactly
            elif step >= iterations or (
                step >= _STALL_AFTER and cost > stall_ratio * costs[-1 - _STALL_LAG]
            ):
                break
            costs.append(cost)
            q = self._step(q, jacobian, error, 1e-9 + self.damping * cost * cost, limited)
            self.steps += 1
        return Descent(False, q, distance, angle, step)

    def _step(
        self, q: np.ndarray, jacobian: np.ndarray, error: np.ndarray, damping: float, limited: bool
    ) -> np.ndarray:
        """The damped least-squares step from ``q``, stopped at the limits when ``limited``."""
        dq = _least_squares(jacobian, error, damping)
        largest = float(np.abs(dq).max())
        if largest > self.max_step:  # a trust region: long steps are only directions
            dq *= self.max_step / largest
        if not self._simple:
            return self._step_on_manifold(q, dq, jacobian, error, damping, limited)
        q_next = q + dq
        if not limited:
            return q_next
        lower, upper = self.chain.lower, self.chain.upper
        within = np.minimum(np.maximum(q_next, lower), upper)
        if (within == q_next).all():
            return q_next
        dq = self._stop_at_limits(dq, lower - q, upper - q, jacobian, error, damping)
        return np.minimum(np.maximum(q + dq, lower), upper)  # rounding only

    def _step_on_manifold(
        self,
        q: np.ndarray,
        dq: np.ndarray,
        jacobian: np.ndarray,
        error: np.ndarray,
        damping: float,
        limited: bool,
    ) -> np.ndarray:
        """``_step`` for a model with (cos, sin) joints: limits in velocity space."""
        if limited:
            now = q[self._q_of_v]
            room_low, room_high = self._v_lower - now, self._v_upper - now
            if ((dq < room_low) | (dq > room_high)).any():
                dq = self._stop_at_limits(dq, room_low, room_high, jacobian, error, damping)
        q_next = pin.integrate(self.model, q, dq)
        if limited:  # rounding only: the step already kept within
            np.clip(q_next, self.chain.lower, self.chain.upper, out=q_next)
        return q_next

    @staticmethod
    def _stop_at_limits(
        dq: np.ndarray,
        room_low: np.ndarray,
        room_high: np.ndarray,
        jacobian: np.ndarray,
        error: np.ndarray,
        damping: float,
    ) -> np.ndarray:
        """The joints whose step would cross a limit stop on it; the others try again."""
        out = (dq < room_low) | (dq > room_high)
        dq = np.clip(dq, room_low, room_high)
        free = ~out
        if free.any():
            rest = error - jacobian[:, out] @ dq[out]
            again = _least_squares(jacobian[:, free], rest, damping)
            dq[free] = np.clip(again, room_low[free], room_high[free])
        return dq


def _least_squares(jacobian: np.ndarray, error: np.ndarray, damping: float) -> np.ndarray:
    """The damped least-squares solution of ``jacobian @ dq = error``."""
    rows, cols = jacobian.shape
    if cols >= rows:
        normal = jacobian @ jacobian.T
        normal += damping * _IDENTITY[rows]
        return jacobian.T @ _solve_spd(normal, error)
    normal = jacobian.T @ jacobian
    normal += damping * _IDENTITY[cols]
    return _solve_spd(normal, jacobian.T @ error)


def _solve_spd(normal: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """``normal^-1 rhs`` for a symmetric positive definite ``normal`` (LAPACK's Cholesky).

    LAPACK's ``dposv`` straight from scipy (which pink's qpsolvers loads anyway):
    a third of ``np.linalg.solve``'s cost on these 3x3 to 6x6 systems.
    """
    _, solution, info = _dposv()(normal, rhs)
    return solution if info == 0 else np.linalg.lstsq(normal, rhs)[0]


@functools.cache
def _dposv() -> Callable[..., Any]:
    """scipy's LAPACK ``dposv``, imported at the first solve: scipy.linalg costs a quarter
    of a second, which a program that never solves IK should not pay at start."""
    from scipy.linalg.lapack import dposv

    return dposv  # type: ignore[no-any-return]
