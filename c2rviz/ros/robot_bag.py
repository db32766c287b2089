"""One robot's topics in a bag, as robot_state_publisher and joint_state_publisher give them.

``BagRobot(writer, robot, namespace)`` writes, for a robot of a recording:
``[/NS]/robot_description`` and its fixed joints on ``/tf_static`` once
(``start``), then with each frame (``frame``) its ``[/NS]/joint_states`` (every
moving joint of the URDF) and its moving joints' transforms on ``/tf``, both
stamped with the frame's time [s]. In a cell each robot has a namespace; its
frames are prefixed with it (``left/base_link``) and ``start`` can place its
root link in the cell's ``world`` frame.
"""

from __future__ import annotations

from collections.abc import Sequence

from ..robot import Robot
from .bag_writer import BagWriter
from .messages import (
    JOINT_STATE,
    frame_prefix,
    joint_state,
    tf_message,
    topic,
    transform,
    transforms,
)
from .tf_tree import TfTree

__all__ = ["BagRobot"]


class BagRobot:
    """The TF and joint states of one robot, written to a ``BagWriter``."""

    def __init__(self, writer: BagWriter, robot: Robot, namespace: str = "") -> None:
        """Prepare the robot's topics (``namespace`` ``""`` for a robot alone).

        Raises:
            MessageError: ``namespace`` is not a ROS name.
            DescriptionError: the robot's URDF joint tree cannot be read.
        """
        self.writer = writer
        self.robot = robot
        self.namespace = namespace
        self.tree = TfTree(robot, frame_prefix(namespace))
        self.topic = topic(namespace, "joint_states")

    def start(
        self,
        t_s: float,
        root_in_world: tuple[Sequence[float], Sequence[float]] | None = None,
        world_frame: str = "world",
    ) -> None:
        """Write the URDF and the fixed joints (and the robot's place in the cell).

        Args:
            t_s: Stamp [s].
            root_in_world: Translation [m] and rotation (x, y, z, w) of the URDF's
                root link in ``world_frame``, or None to leave the robot unplaced.
            world_frame: The cell's frame.
        """
        self.writer.robot_description(t_s, self.robot.source.xml, self.namespace)
        statics = [transform(t_s, *item) for item in self.tree.static_transforms()]
        if root_in_world is not None:
            statics.append(transform(t_s, world_frame, self.tree.root, *root_in_world))
        self.writer.tf_static(t_s, statics)

    def frame(self, t_s: float, chain_q: Sequence[float], chain_v: Sequence[float] = ()) -> None:
        """Write the state at ``t_s`` [s]: joint states and the moving joints' transforms.

        Args:
            t_s: Stamp [s].
            chain_q: The chain's values [rad or m], as ``Robot.configuration`` takes them.
            chain_v: The chain's velocities [rad/s or m/s] while moving, or empty.
        """
        full_q = self.robot.configuration(chain_q)
        names, positions = self.tree.joint_positions(full_q)
        velocities = self.tree.joint_velocities(chain_v) if len(chain_v) else ()
        state = joint_state(t_s, names, positions, velocities)
        self.writer.write(self.topic, JOINT_STATE, t_s, state)
        moving = self.tree.moving_transforms(full_q)
        self.writer.tf(t_s, tf_message(transforms(t_s, moving)))
