"""The CRCL commands that move the arm, stop it or make it wait.

Positions are in the connection's length and angle units (see ``primitives``).
"""

from __future__ import annotations

from dataclasses import dataclass

from .binding import Nested, Record, many, one, opt
from .commands import MiddleCommand
from .errors import CrclValueError
from .primitives import POSE, JointPositionsTolerances, Point, Pose, PoseAndSet
from .scalars import BOOLEAN, DOUBLE, INT, JOINT_NUMBER, NON_NEGATIVE, POSITIVE, enumeration

__all__ = [
    "STOP_CONDITIONS",
    "ActuateJoint",
    "ActuateJoints",
    "Dwell",
    "JointForceTorque",
    "JointSpeedAccel",
    "MoveScrew",
    "MoveThroughTo",
    "MoveTo",
    "StopMotion",
]

STOP_CONDITIONS = ("Immediate", "Fast", "Normal")
"""How a StopMotion stops: drives off at once / fast controlled stop / normal ramp."""


@dataclass(frozen=True, kw_only=True)
class MoveTo(MiddleCommand):
    """Move the tool to ``end_position``: along a straight line if ``move_straight``,
    else along any convenient way (through joint space)."""

    XSI_TYPE = "MoveToType"
    move_straight: bool = one("MoveStraight", BOOLEAN)
    end_position: Pose | PoseAndSet = one("EndPosition", POSE)


@dataclass(frozen=True, kw_only=True)
class MoveThroughTo(MiddleCommand):
    """Move through each waypoint to the last; ``num_positions`` must equal their count
    (at least 2); ``move_straight`` as for MoveTo, for every segment."""

    XSI_TYPE = "MoveThroughToType"
    move_straight: bool = one("MoveStraight", BOOLEAN)
    waypoints: tuple[Pose | PoseAndSet, ...] = many("Waypoint", POSE, min_count=2)
    num_positions: int = one("NumPositions", INT)

    def _check(self) -> None:
        if self.num_positions != len(self.waypoints):
            raise CrclValueError(
                f"NumPositions is {self.num_positions} but there are "
                f"{len(self.waypoints)} Waypoint elements: they must agree"
            )


@dataclass(frozen=True, kw_only=True)
class MoveScrew(MiddleCommand):
    """Screw motion: optionally go to ``start_position`` and advance
    ``axial_distance_free`` [length unit], then turn by ``turn`` [angle unit] while
    advancing ``axial_distance_screw`` [length unit], around the tool axis or, if
    given, around a parallel axis through ``axis_point``."""

    XSI_TYPE = "MoveScrewType"
    start_position: Pose | PoseAndSet | None = opt("StartPosition", POSE)
    axis_point: Point | None = opt("AxisPoint", Nested(Point))
    axial_distance_free: float | None = opt("AxialDistanceFree", DOUBLE)
    axial_distance_screw: float = one("AxialDistanceScrew", DOUBLE)
    turn: float = one("Turn", DOUBLE)


@dataclass(frozen=True, kw_only=True)
class JointSpeedAccel(Record):
    """Speed [unit/s] and acceleration [unit/s^2] for a joint's move; each > 0, optional."""

    XSI_TYPE = "JointSpeedAccelType"
    speed: float | None = opt("JointSpeed", POSITIVE)
    accel: float | None = opt("JointAccel", POSITIVE)


@dataclass(frozen=True, kw_only=True)
class JointForceTorque(Record):
    """Force or torque [force or torque unit] and its rate of change [unit/s] for a joint."""

    XSI_TYPE = "JointForceTorqueType"
    setting: float | None = opt("Setting", DOUBLE)
    change_rate: float | None = opt("ChangeRate", DOUBLE)


@dataclass(frozen=True, kw_only=True)
class ActuateJoint(Record):
    """Move joint ``joint_number`` (from 1) to ``position`` [joint's length or angle
    unit], with ``details`` saying how (speed/accel or force/torque)."""

    XSI_TYPE = "ActuateJointType"
    joint_number: int = one("JointNumber", JOINT_NUMBER)
    position: float = one("JointPosition", DOUBLE)
    details: JointSpeedAccel | JointForceTorque = one(
        "JointDetails", Nested(JointSpeedAccel, JointForceTorque, abstract=True)
    )


@dataclass(frozen=True, kw_only=True)
class ActuateJoints(MiddleCommand):
    """Move some joints (each at most once); the others keep their current setting."""

    XSI_TYPE = "ActuateJointsType"
    joints: tuple[ActuateJoint, ...] = many("ActuateJoint", Nested(ActuateJoint), min_count=1)
    joint_tolerances: JointPositionsTolerances | None = opt(
        "JointTolerances", Nested(JointPositionsTolerances)
    )

    def _check(self) -> None:
        seen: set[int] = set()
        for joint in self.joints:
            if joint.joint_number in seen:
                raise CrclValueError(f"joint {joint.joint_number} appears more than once")
            seen.add(joint.joint_number)


@dataclass(frozen=True, kw_only=True)
class StopMotion(MiddleCommand):
    """Stop the arm; ``condition`` is one of ``STOP_CONDITIONS``."""

    XSI_TYPE = "StopMotionType"
    condition: str = one("StopCondition", enumeration(*STOP_CONDITIONS))


@dataclass(frozen=True, kw_only=True)
class Dwell(MiddleCommand):
    """Wait ``seconds`` [s] (>= 0) before the next command."""

    XSI_TYPE = "DwellType"
    seconds: float = one("DwellTime", NON_NEGATIVE)
