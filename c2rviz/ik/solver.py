"""Inverse kinematics of the chain: chain values that put the tool at a pose.

Poses are the tool point in the robot's base frame (the frame ``Robot.ee_pose``
uses); the tool is an ``SE3`` offset from the end-effector link. pink solves
each step as a small QP (daqp) with the joint limits as constraints; the
solver iterates those steps from the seed, then restarts from other seeds when
an attempt stalls. Pure: no clock, no I/O; the restart seeds come from an rng
seeded anew on every call, so one question always gets one answer.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pink
import pinocchio as pin
from pink.limits import ConfigurationLimit
from pink.tasks import FrameTask, PostureTask

from ..errors import C2rvizError
from ..robot.model import Robot
from .chain import TOOL_FRAME, IkChain
from .tool_task import ToolTask

__all__ = ["Attempt", "IkSettings", "IkSolver", "Unreachable"]

# An attempt stalls when its cost is not 10 % lower than 3 steps before (after 5 steps).
_STALL_AFTER, _STALL_LAG, _STALL_RATIO = 5, 3, 0.9
_POLISH_RATIO = 0.999  # the closest pose of an unreachable target: descend to the bottom


class Unreachable(C2rvizError):
    """No chain values within the limits put the tool at the target pose.

    Attributes:
        distance_m: Position error of the closest tool pose found [m].
        angle_rad: Orientation error of that pose [rad].
    """

    def __init__(self, distance_m: float, angle_rad: float) -> None:
        self.distance_m = distance_m
        self.angle_rad = angle_rad
        super().__init__(
            f"pose unreachable: the closest reachable tool pose is {distance_m * 1e3:.1f} mm "
            f"and {math.degrees(angle_rad):.1f} deg away"
        )


@dataclass(frozen=True)
class IkSettings:
    """How hard the solver tries, and what it calls done.

    Attributes:
        position_tolerance_m: Tool position error accepted [m] (promise: 0.1 mm).
        angle_tolerance_rad: Tool orientation error accepted [rad] (promise: 0.1 deg).
        max_iterations: pink steps per attempt.
        max_attempts: Attempts per solve: the seed, then restarts.
        max_total_iterations: Hard cap on pink steps per solve (about 0.1 ms each)...
        polish_iterations: ...plus these, for the closest pose when unreachable.
        successes_compared: After a restart succeeds, keep restarting until this
            many solutions are found and return the one nearest the seed...
        compare_iterations: ...spending at most this many more pink steps on it.
        max_step: Largest change of any joint in one step [rad or m].
        posture_cost: Pull towards the seed [cost/rad]; small, it only chooses
            among solutions of a redundant arm and is dropped for the last steps.
        orientation_cost: Weight of 1 rad of orientation error against 1 m of
            position error [m/rad]; "closest" when unreachable minimises
            hypot(position error, orientation_cost * angle error).
        seed: Seed of the restart rng.
    """

    position_tolerance_m: float = 1e-5
    angle_tolerance_rad: float = math.radians(0.01)
    max_iterations: int = 20
    max_attempts: int = 16
    max_total_iterations: int = 250
    polish_iterations: int = 100
    successes_compared: int = 2
    compare_iterations: int = 60
    max_step: float = 1.0
    posture_cost: float = 1e-4
    orientation_cost: float = 0.1
    seed: int = 0


@dataclass(frozen=True)
class Attempt:
    """The end of one pink descent.

    Attributes:
        ok: True when the tool is within tolerance of the target.
        q: Chain values reached [rad or m].
        distance_m: Tool position error [m].
        angle_rad: Tool orientation error [rad].
        iterations: pink steps taken.
    """

    ok: bool
    q: tuple[float, ...]
    distance_m: float
    angle_rad: float
    iterations: int


class _Stage:
    """A model pink descends on, with its data and the limits it keeps."""

    def __init__(self, model: pin.Model, limits: list[ConfigurationLimit]) -> None:
        self.model = model
        self.data = model.createData()
        self.limits = limits


class IkSolver:
    """Tool poses to chain values for one robot. Not thread-safe (one pin.Data)."""

    def __init__(self, robot: Robot, settings: IkSettings | None = None) -> None:
        self.robot = robot
        self.settings = s = settings if settings is not None else IkSettings()
        self.chain = IkChain(robot)
        # gain 0.9: a step may close 90 % of the gap to a limit, never cross it
        self._limited = _Stage(self.chain.model, [ConfigurationLimit(self.chain.model, 0.9)])
        # Restarts first descend without limits: joint limits make local minima
        # (a joint pressed against its stop), and a free solution is often in
        # range once revolute joints are wrapped by whole turns. On the bundled
        # arms this lifts one attempt's success from 40-70 % to 70-90 %.
        self._free = _Stage(self.chain.free_model, [])
        # The search descends with pink's FrameTask: from far away its screw error
        # converges more often (41 % against 33 % of single Fanuc attempts); the
        # closest pose of an unreachable target is found with ToolTask, whose
        # Levenberg-Marquardt damping (scaled by the residual) keeps steps going
        # down where full Gauss-Newton steps would overshoot.
        self._frame_task = FrameTask(TOOL_FRAME, 1.0, s.orientation_cost)
        self._tool_task = ToolTask(TOOL_FRAME, s.orientation_cost, lm_damping=1.0)
        self._posture_task = PostureTask(s.posture_cost)

    # --- public -----------------------------------------------------------------------

    def tool_pose(self, q: Sequence[float], tool: pin.SE3 | None = None) -> pin.SE3:
        """Tool placement in the base frame for chain values ``q`` [rad or m]."""
        self.chain.set_tool(tool)
        return self.chain.tool_pose(q)

    def solve(
        self, target: pin.SE3, q_seed: Sequence[float], tool: pin.SE3 | None = None
    ) -> tuple[float, ...]:
        """Chain values within the limits that put the tool at ``target``.

        The first attempt descends from the seed itself; when it stalls, the
        restarts (near the seed, then anywhere) go on until a solution is found
        and, if it is not the seed's own, until ``successes_compared`` are, or
        the budget ends. The answer is the one nearest the seed.

        Args:
            target: Tool pose in the base frame.
            q_seed: Current chain values [rad or m].
            tool: Tool offset from the end-effector link (identity when None).

        Returns:
            Chain values [rad or m] within the limits, the tool within the
            tolerances of ``target``.

        Raises:
            Unreachable: no attempt got there; carries the closest pose's errors.
        """
        s = self.settings
        self.chain.set_tool(tool)
        world_target = self.chain.base_placement * target
        seed = self.chain.to_model(q_seed)
        self._posture_task.set_target(seed)
        rng = np.random.default_rng(s.seed)
        budget = s.max_total_iterations
        found: list[Attempt] = []
        closest: Attempt | None = None
        start = seed

        def steps() -> int:
            return max(0, min(s.max_iterations, budget))

        for index in range(s.max_attempts):
            if index > 0:
                free = self._descend(self._free, start, world_target, steps(), q_seed)
                budget -= free.iterations + 1
                start = self.chain.to_model(free.q)  # whole turns wrapped, then clipped
            attempt = self._descend(self._limited, start, world_target, steps(), q_seed)
            budget -= attempt.iterations + 1
            if attempt.ok:
                if index == 0:
                    return attempt.q  # the seed's own basin: nearest by continuity
                found.append(attempt)
                if len(found) >= s.successes_compared:
                    break
                budget = min(budget, s.compare_iterations)
            elif closest is None or self._cost(attempt) < self._cost(closest):
                closest = attempt
            if budget <= 0:
                break
            start = self._restart(rng, q_seed, index)
        if found:
            distance = [np.linalg.norm(np.subtract(a.q, q_seed)) for a in found]
            return found[int(np.argmin(distance))].q
        assert closest is not None
        # Attempts are cut short when slow; take the closest one to the bottom.
        bottom = self._descend(
            self._limited,
            self.chain.to_model(closest.q),
            world_target,
            s.polish_iterations,
            q_seed,
            _POLISH_RATIO,
            self._tool_task,
        )
        if bottom.ok:  # it was only slow (near a singularity)
            return bottom.q
        raise Unreachable(bottom.distance_m, bottom.angle_rad)

    def follow(
        self, target: pin.SE3, q_start: Sequence[float], tool: pin.SE3 | None = None
    ) -> Attempt:
        """One descent from ``q_start`` towards ``target``, no restarts (for paths).

        The posture pull is towards ``q_start``, so a redundant arm moves little.
        """
        self.chain.set_tool(tool)
        start = self.chain.to_model(q_start)
        self._posture_task.set_target(start)
        return self._descend(
            self._limited,
            start,
            self.chain.base_placement * target,
            self.settings.max_iterations,
            q_start,
        )

    # --- the descent ------------------------------------------------------------------

    def _cost(self, attempt: Attempt) -> float:
        return self.cost(attempt.distance_m, attempt.angle_rad)

    def cost(self, distance_m: float, angle_rad: float) -> float:
        """How far a pose is from the target, the norm pink minimises [m]."""
        return math.hypot(distance_m, self.settings.orientation_cost * angle_rad)

    def _restart(self, rng: np.random.Generator, q_seed: Sequence[float], index: int) -> np.ndarray:
        """Every other restart is near the seed (a widening box), the rest anywhere."""
        q = np.array(self.robot.random(rng))
        if index % 2 == 0:
            width = min(1.0, 0.15 * (index // 2 + 1))
            q = np.asarray(q_seed) + width * (q - np.asarray(q_seed))
        return self.chain.to_model(q.tolist())

    def _descend(
        self,
        stage: _Stage,
        q0: np.ndarray,
        world_target: pin.SE3,
        iterations: int,
        near: Sequence[float],
        stall_ratio: float = _STALL_RATIO,
        pose_task: FrameTask | ToolTask | None = None,
    ) -> Attempt:
        """Up to ``iterations`` pink steps from ``q0``, fewer when it converges or stalls."""
        s = self.settings
        configuration = pink.Configuration(stage.model, stage.data, q0, copy_data=False)
        if pose_task is None:
            pose_task = self._frame_task
            pose_task.set_target(world_target)
        else:
            pose_task.target = world_target
        tasks_far = [pose_task, self._posture_task]
        tasks_near = [pose_task]
        costs: list[float] = []
        distance = angle = math.inf
        step = 0
        for step in range(iterations + 1):  # noqa: B007 (step is read after the loop)
            placement = configuration.data.oMf[self.chain.tool_frame]
            distance = float(np.linalg.norm(world_target.translation - placement.translation))
            angle = float(np.linalg.norm(pin.log3(placement.rotation.T @ world_target.rotation)))
            if distance <= s.position_tolerance_m and angle <= s.angle_tolerance_rad:
                return Attempt(
                    True, self.chain.to_chain(configuration.q, near), distance, angle, step
                )
            costs.append(self.cost(distance, angle))
            # stalled: under 10 % better than three steps ago (a local minimum or a limit)
            if step == iterations or (
                step >= _STALL_AFTER and costs[-1] > stall_ratio * costs[-1 - _STALL_LAG]
            ):
                break
            # The posture pull would leave a tiny steady error near singularities;
            # within 1 mm and 1 deg the null-space choice is made, so drop it.
            near_target = distance < 1e-3 and angle < math.radians(1.0)
            velocity = pink.solve_ik(
                configuration,
                tasks_near if near_target else tasks_far,
                1.0,  # dt: one step is one displacement, the velocity is the step
                solver="daqp",
                damping=1e-12,
                limits=stage.limits,  # position limits only: no velocity limit per step
            )
            largest = float(np.abs(velocity).max())
            if largest > s.max_step:  # a trust region: scale the Gauss-Newton step down
                velocity *= s.max_step / largest
            # DAQP meets the limits to its tolerance (~1e-6); clip so every q is within
            q_next = pin.integrate(stage.model, configuration.q, velocity)
            if stage.limits:
                q_next = np.clip(q_next, self.chain.lower, self.chain.upper)
            configuration.update(q_next)
        return Attempt(False, self.chain.to_chain(configuration.q, near), distance, angle, step)
