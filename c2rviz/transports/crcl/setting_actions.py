"""What c2rviz does with the CRCL commands that change a setting: ``SETTING_ACTIONS``.

Units, speeds, accelerations, tolerances, which parts and joints a status reports,
and ``Message``. Each is done at once (``CRCL_Done``); where c2rviz only keeps a
setting for the statuses, the returned text says so in the ``StateDescription``.
Speeds map to the session's own: ``SetTransSpeed`` absolute is ``lspeed`` (the
straight moves' tool speed), a relative speed is ``speed`` (the moves' share of the
joints' limits).
"""

from __future__ import annotations

from typing import Any, Final

from .commands import (
    ConfigureJointReport,
    ConfigureJointReports,
    ConfigureStatusReport,
    Message,
)
from .controller import Action, Controller, Refused, Report, registrar
from .primitives import RotSpeedRelative, TransSpeedAbsolute, TransSpeedRelative
from .setting_commands import (
    SetAngleUnits,
    SetDefaultJointPositionsTolerances,
    SetEndPoseTolerance,
    SetForceUnits,
    SetIntermediatePoseTolerance,
    SetLengthUnits,
    SetMotionCoordination,
    SetRotAccel,
    SetRotSpeed,
    SetTorqueUnits,
    SetTransAccel,
    SetTransSpeed,
)

__all__ = ["LSPEED_RANGE", "MIN_FRACTION", "SETTING_ACTIONS"]

MIN_FRACTION: Final = 0.01
"""The least relative speed (as the text port's ``speed 1``, 1 % of the limits)."""
LSPEED_RANGE: Final = (1e-3, 5.0)
"""The tool speeds a straight move takes [m/s] (the text port's ``lspeed`` allows 0..5)."""

SETTING_ACTIONS: dict[type, Action] = {}
_action = registrar(SETTING_ACTIONS)


@_action(SetLengthUnits)
def _length_units(ctl: Controller, report: Report, command: SetLengthUnits) -> None:
    ctl.settings.length_unit = command.unit


@_action(SetAngleUnits)
def _angle_units(ctl: Controller, report: Report, command: SetAngleUnits) -> None:
    ctl.settings.angle_unit = command.unit
    ctl.session.set_degrees(command.unit == "degree")  # its limit errors speak the unit


@_action(SetForceUnits, SetTorqueUnits)
def _force_units(ctl: Controller, report: Report, command: SetForceUnits) -> str:
    if isinstance(command, SetForceUnits):
        ctl.settings.force_unit = command.unit
    else:
        ctl.settings.torque_unit = command.unit
    return "kept for the statuses: c2rviz reports no forces or torques"


@_action(SetTransSpeed)
def _trans_speed(ctl: Controller, report: Report, command: SetTransSpeed) -> None:
    speed = command.speed
    if isinstance(speed, TransSpeedAbsolute):
        m_s = speed.setting * ctl.settings.length
        low, high = LSPEED_RANGE
        if not low <= m_s <= high:
            unit = ctl.settings.length_unit
            raise Refused(
                f"{speed.setting:g} {unit}/s is outside {low / ctl.settings.length:g}.."
                f"{high / ctl.settings.length:g} {unit}/s (0.001..5 m/s)"
            )
        ctl.session.set_lspeed(m_s)
    else:
        _set_fraction(ctl, speed)
    ctl.settings.trans_speed = speed


@_action(SetRotSpeed)
def _rot_speed(ctl: Controller, report: Report, command: SetRotSpeed) -> str | None:
    ctl.settings.rot_speed = command.speed
    if isinstance(command.speed, RotSpeedRelative):
        _set_fraction(ctl, command.speed)
        return None
    return "kept: the tool turns as fast as the joints' share of their limits allows"


def _set_fraction(ctl: Controller, speed: TransSpeedRelative | RotSpeedRelative) -> None:
    if speed.fraction < MIN_FRACTION:
        raise Refused(f"a fraction of {speed.fraction:g} is below {MIN_FRACTION:g} (1 %)")
    ctl.session.set_speed(speed.fraction * 100.0)


@_action(SetTransAccel, SetRotAccel)
def _accel(ctl: Controller, report: Report, command: SetTransAccel | SetRotAccel) -> str:
    if isinstance(command, SetTransAccel):
        ctl.settings.trans_accel = command.accel
    else:
        ctl.settings.rot_accel = command.accel
    return "kept: accelerations follow the speed (the joints' limits scaled together)"


@_action(SetEndPoseTolerance, SetIntermediatePoseTolerance, SetDefaultJointPositionsTolerances)
def _tolerance(ctl: Controller, report: Report, command: Any) -> str:
    if isinstance(command, SetEndPoseTolerance):
        ctl.settings.end_pose_tolerance = command.tolerance
    elif isinstance(command, SetIntermediatePoseTolerance):
        ctl.settings.intermediate_pose_tolerance = command.tolerance
    else:
        ctl.settings.joint_tolerances = command.joint_tolerances
    return "kept: c2rviz reaches poses within 0.1 mm and 0.1 deg, joints exactly"


@_action(SetMotionCoordination)
def _coordination(ctl: Controller, report: Report, command: SetMotionCoordination) -> None:
    ctl.settings.motion_coordinated = command.coordinated


@_action(ConfigureJointReports)
def _joint_reports(ctl: Controller, report: Report, command: ConfigureJointReports) -> None:
    n = ctl.session.n
    for entry in command.reports:
        if entry.joint_number > n:
            raise Refused(
                f"joint {entry.joint_number} does not exist: {ctl.session.state.name} has "
                f"joints 1..{n}"
            )
    reports: dict[int, ConfigureJointReport] = {}
    if not command.reset_all:  # from what was reported: each joint's position by default
        reports = dict(ctl.settings.joint_reports or _every_position(n))
    for entry in command.reports:
        reports[entry.joint_number] = entry
    ctl.settings.joint_reports = reports


def _every_position(n: int) -> dict[int, ConfigureJointReport]:
    return {
        number: ConfigureJointReport(
            joint_number=number,
            report_position=True,
            report_torque_or_force=False,
            report_velocity=False,
        )
        for number in range(1, n + 1)
    }


@_action(ConfigureStatusReport)
def _status_report(ctl: Controller, report: Report, command: ConfigureStatusReport) -> None:
    ctl.settings.status_report = command


@_action(Message)
def _message(ctl: Controller, report: Report, command: Message) -> None:
    ctl.session.said(f"{report.what}: {command.message[:200]}").accept()
