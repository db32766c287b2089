"""What the world holds of each robot: its joints, markers, tool and place in the cell.

``RobotState`` is one robot of the world; ``Marker`` one of its markers, in the
world frame. Values are SI (radians, metres). Only the world writes them; everyone
else reads.

``MoveRules`` is what faults make of moves: the hooks ``Travels`` asks
(``fault_rules.FaultRules`` fills them in); the base changes nothing.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field

import pinocchio as pin

from ..errors import C2rvizError
from ..robot.model import Robot

MAX_MARKERS = 1000
"""Markers kept at once per robot; beyond it the oldest goes first, so a flood of
``mark`` costs neither the server's memory nor the page's frame rate. Every holder
of markers keeps them in a ``deque(maxlen=MAX_MARKERS)``."""


@dataclass(frozen=True, slots=True)
class Marker:
    """A marker in the world frame (the root of the robot's model).

    Attributes:
        position: x, y, z [m].
        wxyz: Orientation as a unit quaternion.
        rgb: Colour, each channel 0..1.
        shape: One of ``protocol.MARKER_SHAPES``.
    """

    position: tuple[float, float, float]
    wxyz: tuple[float, float, float, float]
    rgb: tuple[float, float, float]
    shape: str


@dataclass(eq=False)
class RobotState:
    """One robot of the world.

    Attributes:
        name: The robot's name in this world (what ``robot NAME`` selects).
        robot: Its model and chain.
        q: The chain's values shown now [rad or m].
        target: The values it was last commanded to [rad or m].
        markers: Its markers, in the world frame, oldest first.
        origin: Where its model's root stands in the world (the cell) frame.
        port: The command port that drives it by default (None: not known here).
        tool: The tool point (TCP) relative to the end-effector link.
        opening: Its gripper's opening shown now, 0 closed .. 1 open (0 without one).
        opening_target: The opening it was last commanded to.
        ghost: Views show where it travels: its target and its path (``ghost on|off``).
    """

    name: str
    robot: Robot
    q: tuple[float, ...] = ()
    target: tuple[float, ...] = ()
    markers: deque[Marker] = field(default_factory=lambda: deque(maxlen=MAX_MARKERS))
    origin: pin.SE3 = field(default_factory=pin.SE3.Identity)
    port: int | None = None
    tool: pin.SE3 = field(default_factory=pin.SE3.Identity)
    opening: float = 0.0
    opening_target: float = 0.0
    ghost: bool = True

    def __post_init__(self) -> None:
        if not self.q:
            self.q = self.target = self.robot.home
        gripper = self.robot.gripper
        if gripper is not None:  # where its fingers stand in the model's neutral pose
            at_rest = [float(self.robot.neutral[i]) for i in gripper.idx_q]
            self.opening = self.opening_target = gripper.opening_of(at_rest)

    @property
    def base(self) -> pin.SE3:
        """The robot's base frame (where poses are given) in the world frame."""
        return self.origin * self.robot.base_placement


class MoveRules:
    """What faults make of moves; this base changes nothing."""

    def refuse(self, state: RobotState) -> None:
        """Raise if a move of ``state`` is refused now."""

    def follow(self, state: RobotState, q: tuple[float, ...]) -> tuple[float, ...]:
        """Where ``state``'s joints are when commanded to ``q``."""
        return q

    def arrival_error(self, state: RobotState) -> C2rvizError | None:
        """The error a move that came to rest at its target ends with (None: ``ok``)."""
        return None
