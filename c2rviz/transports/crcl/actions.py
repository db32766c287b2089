"""What c2rviz does with each CRCL command: ``ACTIONS`` maps every command type to it.

An action runs when its command arrives (after the canon and guard checks of the
``Controller``). It changes a setting and returns (the command is then
``CRCL_Done``, with the returned text as its ``StateDescription`` when it says what
c2rviz made of it), starts a job that takes time (``motions``; ``CRCL_Working`` until
it ends), or raises ``Refused`` (or any ``C2rvizError``): ``CRCL_Error`` with the why.
What a virtual arm cannot do (tool changers, sensors, force control, native programs)
is refused, never silently accepted. See docs/crcl.md for the table.

The commands that change a setting (``SETTING_ACTIONS``): units, speeds, accelerations,
tolerances, which parts and joints a status reports, and ``Message``. Each is done at
once (``CRCL_Done``); where c2rviz only keeps a setting for the statuses, the returned
text says so in the ``StateDescription``. Speeds map to the session's own:
``SetTransSpeed`` absolute is ``lspeed`` (the straight moves' tool speed), a relative
speed is ``speed`` (the moves' share of the joints' limits).
"""

from __future__ import annotations

import math
from typing import Any, Final

from ...errors import NoGripper
from .commands import (
    ActuateJoints,
    CloseToolChanger,
    ConfigureJointReport,
    ConfigureJointReports,
    ConfigureStatusReport,
    DisableGripper,
    DisableRobotParameterStatus,
    DisableSensor,
    Dwell,
    EnableGripper,
    EnableRobotParameterStatus,
    EnableSensor,
    EndCanon,
    InitCanon,
    JointForceTorque,
    JointSpeedAccel,
    LoopBlockEnd,
    LoopBlockStart,
    Message,
    MoveScrew,
    MoveThroughTo,
    MoveTo,
    OpenToolChanger,
    RunProgram,
    SetEndEffector,
    StopMotion,
)
from .controller import ARM, DWELL, GRIPPER, Action, Controller, Refused, Report, registrar
from .documents import COMMAND_TYPES
from .motions import Placements, actuate, dwell, grip, halt, move_through, move_to, placement
from .primitives import RotSpeedRelative, TransSpeedAbsolute, TransSpeedRelative
from .setting_commands import (
    SetAngleUnits,
    SetDefaultJointPositionsTolerances,
    SetEndEffectorParameters,
    SetEndPoseTolerance,
    SetForceUnits,
    SetIntermediatePoseTolerance,
    SetLengthUnits,
    SetMotionCoordination,
    SetRobotParameters,
    SetRotAccel,
    SetRotSpeed,
    SetTorqueUnits,
    SetTransAccel,
    SetTransSpeed,
)

ACTIONS: dict[type, Action] = {}
"""What each command type does (GetStatus is the controller's own)."""
_action = registrar(ACTIONS)


# The canon.


@_action(InitCanon)
def _init_canon(ctl: Controller, report: Report, command: InitCanon) -> None:
    ctl.canon, ctl.ended = True, False


@_action(EndCanon)
def _end_canon(ctl: Controller, report: Report, command: EndCanon) -> None:
    ctl.canon, ctl.ended = False, True
    _halt(ctl, report, (GRIPPER, DWELL))


def _halt(ctl: Controller, report: Report, takes: tuple[str, ...]) -> None:
    """Stop what this connection runs in ``ARM`` and ``takes``, and the arm and fingers
    (done at once if nothing moves)."""
    session = ctl.session
    if session.travel.active or session.world.grips.moving(session.state):
        ctl.start(ARM, report, halt, takes=takes)
    else:
        for lane in (ARM, *takes):
            ctl.take_over(lane, report)


# Motion.


@_action(MoveTo)
def _move_to(ctl: Controller, report: Report, command: MoveTo) -> None:
    target = placement(command.end_position, ctl.settings.length_unit)
    ctl.start(ARM, report, lambda c, job: move_to(c, job, target, command.move_straight))


@_action(MoveThroughTo)
def _move_through(ctl: Controller, report: Report, command: MoveThroughTo) -> None:
    targets = Placements(command.waypoints, ctl.settings.length_unit)
    ctl.start(ARM, report, lambda c, job: move_through(c, job, targets, command.move_straight))


@_action(ActuateJoints)
def _actuate(ctl: Controller, report: Report, command: ActuateJoints) -> None:
    session = ctl.session
    n, robot = session.n, session.robot
    limits = session.world.motion_limits(session.state.name)
    factors = ctl.settings.joint_factors(robot.prismatic)
    indices, values, fractions = [], [], []
    for joint in command.joints:
        index = joint.joint_number - 1
        if index >= n:
            raise Refused(
                f"joint {joint.joint_number} does not exist: {session.state.name} has joints "
                f"1..{n} (JointNumber counts from 1)"
            )
        details = joint.details
        if isinstance(details, JointForceTorque):
            raise Refused(f"joint {joint.joint_number}: force or torque control is not simulated")
        indices.append(index)
        # The session speaks the connection's angle unit, and meters.
        scale = factors[index] if robot.prismatic[index] else 1.0
        values.append(joint.position * scale)
        if isinstance(details, JointSpeedAccel):
            if details.speed is not None:
                fractions.append(details.speed * factors[index] / limits.velocity[index])
            if details.accel is not None:
                fractions.append(
                    math.sqrt(details.accel * factors[index] / limits.acceleration[index])
                )
    q = list(session.state.target)
    for index, value in zip(indices, session.to_si(indices, values)):
        q[index] = value
    fraction = min(fractions) if fractions else session.speed / 100.0
    fraction = min(max(fraction, MIN_FRACTION), 1.0)
    ctl.start(ARM, report, lambda c, job: actuate(c, job, q, fraction))


@_action(StopMotion)
def _stop(ctl: Controller, report: Report, command: StopMotion) -> None:
    _halt(ctl, report, (GRIPPER,))


@_action(Dwell)
def _dwell(ctl: Controller, report: Report, command: Dwell) -> None:
    longest = ctl.session.limits.max_sleep_s
    if command.seconds > longest:
        raise Refused(f"{command.seconds:g} s is over the limit of {longest:g} s (max_sleep)")
    ctl.start(DWELL, report, lambda c, job: dwell(c, job, command.seconds))


# The gripper.


def _gripper(ctl: Controller, name: str | None = None) -> None:
    state = ctl.session.state
    gripper = state.robot.gripper
    if gripper is None:
        raise NoGripper(state.name)
    if name is not None and name != gripper.name:
        raise Refused(f"no gripper {name!r}: {state.name}'s gripper is {gripper.name!r}")


@_action(SetEndEffector)
def _end_effector(ctl: Controller, report: Report, command: SetEndEffector) -> None:
    _gripper(ctl)
    if not ctl.settings.gripper_enabled:
        raise Refused("the gripper is disabled (DisableGripper): send EnableGripper first")
    ctl.start(GRIPPER, report, lambda c, job: grip(c, job, command.setting))


@_action(SetEndEffectorParameters)
def _end_effector_parameters(
    ctl: Controller, report: Report, command: SetEndEffectorParameters
) -> str:
    _gripper(ctl)
    ctl.settings.end_effector_parameters = command.parameters
    return "kept for the statuses: c2rviz's gripper has no parameters to set"


@_action(EnableGripper, DisableGripper)
def _enable_gripper(ctl: Controller, report: Report, command: Any) -> None:
    _gripper(ctl, command.gripper_name)
    ctl.settings.gripper_enabled = isinstance(command, EnableGripper)


# What a virtual arm cannot do.

_REFUSALS: dict[type, str] = {
    MoveScrew: "screw motions are not supported (MoveTo, MoveThroughTo and ActuateJoints are)",
    OpenToolChanger: "c2rviz's arm has no tool changer",
    CloseToolChanger: "c2rviz's arm has no tool changer",
    SetRobotParameters: "c2rviz's arm has no robot parameters",
    EnableRobotParameterStatus: "c2rviz's arm has no robot parameters to report",
    DisableRobotParameterStatus: "c2rviz's arm has no robot parameters to report",
    RunProgram: "c2rviz runs no native programs: send CRCL commands (c2rviz-play runs a "
    "CRCLProgram file)",
    LoopBlockStart: "loop blocks are not supported: unroll the loop",
    LoopBlockEnd: "loop blocks are not supported: unroll the loop",
}


def _refuse(ctl: Controller, report: Report, command: Any) -> None:
    raise Refused(_REFUSALS[type(command)])


@_action(EnableSensor, DisableSensor)
def _sensor(ctl: Controller, report: Report, command: EnableSensor | DisableSensor) -> None:
    raise Refused(f"no sensor {command.sensor_id[:40]!r}: c2rviz simulates no sensors")


for _kind in _REFUSALS:
    ACTIONS[_kind] = _refuse


# The settings.

MIN_FRACTION: Final = 0.01
"""The least relative speed (as the text port's ``speed 1``, 1 % of the limits)."""
LSPEED_RANGE: Final = (1e-3, 5.0)
"""The tool speeds a straight move takes [m/s] (the text port's ``lspeed`` allows 0..5)."""

SETTING_ACTIONS: dict[type, Action] = {}
_setting = registrar(SETTING_ACTIONS)


@_setting(SetLengthUnits)
def _length_units(ctl: Controller, report: Report, command: SetLengthUnits) -> None:
    ctl.settings.length_unit = command.unit


@_setting(SetAngleUnits)
def _angle_units(ctl: Controller, report: Report, command: SetAngleUnits) -> None:
    ctl.settings.angle_unit = command.unit
    ctl.session.set_degrees(command.unit == "degree")  # its limit errors speak the unit


@_setting(SetForceUnits, SetTorqueUnits)
def _force_units(ctl: Controller, report: Report, command: SetForceUnits) -> str:
    if isinstance(command, SetForceUnits):
        ctl.settings.force_unit = command.unit
    else:
        ctl.settings.torque_unit = command.unit
    return "kept for the statuses: c2rviz reports no forces or torques"


@_setting(SetTransSpeed)
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


@_setting(SetRotSpeed)
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


@_setting(SetTransAccel, SetRotAccel)
def _accel(ctl: Controller, report: Report, command: SetTransAccel | SetRotAccel) -> str:
    if isinstance(command, SetTransAccel):
        ctl.settings.trans_accel = command.accel
    else:
        ctl.settings.rot_accel = command.accel
    return "kept: accelerations follow the speed (the joints' limits scaled together)"


@_setting(SetEndPoseTolerance, SetIntermediatePoseTolerance, SetDefaultJointPositionsTolerances)
def _tolerance(ctl: Controller, report: Report, command: Any) -> str:
    if isinstance(command, SetEndPoseTolerance):
        ctl.settings.end_pose_tolerance = command.tolerance
    elif isinstance(command, SetIntermediatePoseTolerance):
        ctl.settings.intermediate_pose_tolerance = command.tolerance
    else:
        ctl.settings.joint_tolerances = command.joint_tolerances
    return "kept: c2rviz reaches poses within 0.1 mm and 0.1 deg, joints exactly"


@_setting(SetMotionCoordination)
def _coordination(ctl: Controller, report: Report, command: SetMotionCoordination) -> None:
    ctl.settings.motion_coordinated = command.coordinated


@_setting(ConfigureJointReports)
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


@_setting(ConfigureStatusReport)
def _status_report(ctl: Controller, report: Report, command: ConfigureStatusReport) -> None:
    ctl.settings.status_report = command


@_setting(Message)
def _message(ctl: Controller, report: Report, command: Message) -> None:
    ctl.session.said(f"{report.what}: {command.message[:200]}").accept()


ACTIONS.update(SETTING_ACTIONS)
_missing = [kind.__name__ for kind in COMMAND_TYPES if kind not in ACTIONS]
assert _missing == ["GetStatus"], _missing  # GetStatus is the controller's own
