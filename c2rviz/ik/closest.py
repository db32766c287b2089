"""The closest pose to an unreachable target: a descent taken to the bottom with pink.

The Newton descents stop where a joint limit makes a corner; pink's QP (daqp)
keeps every limit as a constraint, so its least-squares bottom is the pose
closest by ``hypot(distance, orientation_cost * angle)`` that the limits allow.
Used only for refusals (and the rare slow answer near a singularity), so its
cost (some 0.1 ms a step) is paid off the common path. ``ToolTask`` is the pink task
that measures the tool's error as we report it.
"""

from __future__ import annotations

import math

import numpy as np
import pink
import pinocchio as pin
from pink.limits import ConfigurationLimit
from pink.tasks import PostureTask, Task

from .chain import TOOL_FRAME, Goal, IkChain
from .newton import Descent, NewtonDescent

_STALL_AFTER, _STALL_LAG, _STALL_RATIO = 5, 3, 0.999  # descend to the bottom


class ToolTask(Task):
    """Drive a frame to a target pose: position difference and rotation vector.

    pink's ``FrameTask`` measures the error as a screw (``log6``), whose linear
    part is not the distance between the two points once the orientations
    differ. Here the error is the position difference in the world frame [m]
    and the rotation vector from the target to the frame's orientation [rad],
    so the least-squares bottom pink reaches for an unreachable target is the
    pose closest by ``hypot(distance, orientation_cost * angle)``.

    Attributes:
        frame: Name of the driven frame.
        target: Its target placement in the world frame.
    """

    def __init__(self, frame: str, orientation_cost: float, lm_damping: float = 0.0) -> None:
        """Weigh 1 rad like ``orientation_cost`` metres [m/rad]; see ``Task`` for the damping."""
        super().__init__(
            cost=np.array([1.0, 1.0, 1.0] + [orientation_cost] * 3), lm_damping=lm_damping
        )
        self.frame = frame
        self.target = pin.SE3.Identity()

    def compute_error(self, configuration: pink.Configuration) -> np.ndarray:
        """Position difference [m] (world axes), then rotation vector [rad] (target axes)."""
        pose = configuration.get_transform_frame_to_world(self.frame)
        return np.concatenate(
            [
                pose.translation - self.target.translation,
                pin.log3(self.target.rotation.T @ pose.rotation),
            ]
        )

    def compute_jacobian(self, configuration: pink.Configuration) -> np.ndarray:
        """Derivative of ``compute_error`` with respect to the configuration."""
        pose = configuration.get_transform_frame_to_world(self.frame)
        local = configuration.get_frame_jacobian(self.frame)  # body velocity of the frame
        rotation_error = self.target.rotation.T @ pose.rotation
        return np.vstack([pose.rotation @ local[:3], pin.Jlog3(rotation_error) @ local[3:]])

    def __repr__(self) -> str:
        return f"ToolTask(frame={self.frame}, cost={self.cost})"


class ClosestPose:
    """pink descents to the bottom of the weighted pose error, within the limits.

    Args:
        chain: The chain (its model; ``set_tool`` is seen at once).
        orientation_cost: Weight of 1 rad against 1 m [m/rad].
        posture_cost: Pull towards the start, dropped within 1 mm and 1 deg [cost/rad].
    """

    def __init__(self, chain: IkChain, orientation_cost: float, posture_cost: float) -> None:
        self.chain = chain
        self.data = chain.model.createData()
        # gain 0.9: a step may close 90 % of the gap to a limit, never cross it
        self.limits = [ConfigurationLimit(chain.model, 0.9)]
        # Levenberg-Marquardt damping (scaled by the residual) keeps steps going down
        # where full Gauss-Newton steps would overshoot.
        self.pose_task = ToolTask(TOOL_FRAME, orientation_cost, lm_damping=1.0)
        self.point_task = ToolTask(TOOL_FRAME, 0.0, lm_damping=1.0)
        self.posture_task = PostureTask(posture_cost)
        self.steps = 0

    def descend(
        self, q0: np.ndarray, goal: Goal, iterations: int, newton: NewtonDescent
    ) -> Descent:
        """Up to ``iterations`` pink steps from ``q0``; ``newton`` says what counts as there."""
        model = self.chain.model
        configuration = pink.Configuration(model, self.data, q0, copy_data=False)
        free = goal.rotation is None
        task = self.point_task if free else self.pose_task
        rotation = np.eye(3) if goal.rotation is None else goal.rotation
        task.target = pin.SE3(rotation, goal.position)
        self.posture_task.set_target(q0)
        tasks_far = [task, self.posture_task]
        tasks_near = [task]
        costs: list[float] = []
        distance = angle = math.inf
        step = 0
        for step in range(iterations + 1):  # noqa: B007 (step is read after the loop)
            placement = configuration.data.oMf[self.chain.tool_frame]
            distance = float(np.linalg.norm(goal.position - placement.translation))
            turn = pin.log3(placement.rotation.T @ rotation)
            angle = 0.0 if free else float(np.linalg.norm(turn))
            if distance <= newton.position_tolerance_m and angle <= newton.angle_tolerance_rad:
                return Descent(True, configuration.q, distance, angle, step)
            costs.append(math.hypot(distance, newton.weight * angle))
            if step == iterations or (
                step >= _STALL_AFTER and costs[-1] > _STALL_RATIO * costs[-1 - _STALL_LAG]
            ):
                break
            # The posture pull would leave a tiny steady error near singularities;
            # within 1 mm and 1 deg the null-space choice is made, so drop it.
            near = distance < 1e-3 and angle < math.radians(1.0)
            velocity = pink.solve_ik(
                configuration,
                tasks_near if near else tasks_far,
                1.0,  # dt: one step is one displacement, the velocity is the step
                solver="daqp",
                damping=1e-12,
                limits=self.limits,  # position limits only: no velocity limit per step
            )
            largest = float(np.abs(velocity).max())
            if largest > newton.max_step:  # a trust region: scale the step down
                velocity *= newton.max_step / largest
            # DAQP meets the limits to its tolerance (~1e-6); clip so every q is within
            q_next = pin.integrate(model, configuration.q, velocity)
            configuration.update(np.clip(q_next, self.chain.lower, self.chain.upper))
            self.steps += 1
        return Descent(False, configuration.q, distance, angle, step)
