"""A pink task that drives a frame to a pose, its error measured as we report it."""

from __future__ import annotations

import numpy as np
import pink
import pinocchio as pin
from pink.tasks import Task

__all__ = ["ToolTask"]


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
