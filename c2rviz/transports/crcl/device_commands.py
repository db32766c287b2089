"""The CRCL commands for the end effector, tool changer, grippers, sensors and the
robot-parameter reports."""

from __future__ import annotations

from dataclasses import dataclass

from .binding import Nested, many, one
from .commands import MiddleCommand
from .primitives import ParameterSetting
from .scalars import FRACTION, NMTOKEN, TOKEN

__all__ = [
    "CloseToolChanger",
    "DisableGripper",
    "DisableRobotParameterStatus",
    "DisableSensor",
    "EnableGripper",
    "EnableRobotParameterStatus",
    "EnableSensor",
    "OpenToolChanger",
    "SetEndEffector",
]


@dataclass(frozen=True, kw_only=True)
class SetEndEffector(MiddleCommand):
    """Set the end effector to ``setting``, a fraction 0..1: for a gripper 0 is
    closed and 1 fully open; for an on/off tool 0 is off and anything above is on."""

    XSI_TYPE = "SetEndEffectorType"
    setting: float = one("Setting", FRACTION)


@dataclass(frozen=True, kw_only=True)
class OpenToolChanger(MiddleCommand):
    """Release the mounted end effector (the controlled point changes)."""

    XSI_TYPE = "OpenToolChangerType"


@dataclass(frozen=True, kw_only=True)
class CloseToolChanger(MiddleCommand):
    """Mount the end effector the tool changer is at (the controlled point changes)."""

    XSI_TYPE = "CloseToolChangerType"


@dataclass(frozen=True, kw_only=True)
class EnableGripper(MiddleCommand):
    """Enable the gripper ``gripper_name``, with device-specific options."""

    XSI_TYPE = "EnableGripperType"
    gripper_name: str = one("GripperName", NMTOKEN)
    options: tuple[ParameterSetting, ...] = many("GripperOption", Nested(ParameterSetting))


@dataclass(frozen=True, kw_only=True)
class DisableGripper(MiddleCommand):
    """Disable the gripper ``gripper_name``."""

    XSI_TYPE = "DisableGripperType"
    gripper_name: str = one("GripperName", NMTOKEN)


@dataclass(frozen=True, kw_only=True)
class EnableSensor(MiddleCommand):
    """Start reporting the sensor ``sensor_id``, with device-specific options."""

    XSI_TYPE = "EnableSensorType"
    sensor_id: str = one("SensorID", TOKEN)
    options: tuple[ParameterSetting, ...] = many("SensorOption", Nested(ParameterSetting))


@dataclass(frozen=True, kw_only=True)
class DisableSensor(MiddleCommand):
    """Stop reporting the sensor ``sensor_id``."""

    XSI_TYPE = "DisableSensorType"
    sensor_id: str = one("SensorID", TOKEN)


@dataclass(frozen=True, kw_only=True)
class EnableRobotParameterStatus(MiddleCommand):
    """Start reporting the robot parameter ``parameter_name`` in statuses."""

    XSI_TYPE = "EnableRobotParameterStatusType"
    parameter_name: str = one("RobotParameterName", TOKEN)


@dataclass(frozen=True, kw_only=True)
class DisableRobotParameterStatus(MiddleCommand):
    """Stop reporting the robot parameter ``parameter_name``."""

    XSI_TYPE = "DisableRobotParameterStatusType"
    parameter_name: str = one("RobotParameterName", TOKEN)
