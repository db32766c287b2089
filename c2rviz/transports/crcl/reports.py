"""What a CRCL connection has set, and the parts of its statuses, read from the world.

``ConnectionSettings`` holds what the Set... and Configure... commands of one
connection set: its units (meter and radian until told otherwise), the speeds and
tolerances as sent, which joints its statuses report and which parts. The functions
below build each part of a ``CrclStatus`` in those units from the world as it is
at this instant (mid-move too): ``pose_status`` (the tool point in the base frame),
``joint_statuses``, ``gripper_status`` and ``settings_status``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TypeVar

from ...session.session import Session
from .binding import Nested, record_fields, write_record
from .commands import ConfigureJointReport, ConfigureStatusReport
from .documents import ROOT_ATTRIBUTES, XML_DECLARATION
from .primitives import (
    JointPositionsTolerances,
    ParameterSetting,
    Point,
    Pose,
    PoseTolerance,
    RotAccelAbsolute,
    RotAccelRelative,
    RotSpeedAbsolute,
    RotSpeedRelative,
    TransAccelAbsolute,
    TransAccelRelative,
    TransSpeedAbsolute,
    TransSpeedRelative,
    Vector,
)
from .status import (
    CrclStatus,
    JointLimit,
    JointStatus,
    JointStatuses,
    ParallelGripperStatus,
    PoseStatus,
    SettingsStatus,
)
from .units import angle_factor, joint_factors, length_factor, matrix_to_pose

_STATUS_PARTS = record_fields(CrclStatus)  # the status's elements, in the schema's order

T = TypeVar("T")
_VELOCITY_DT_S = 1e-3  # a path's joint velocity: its positions this far apart [s]


@dataclass
class ConnectionSettings:
    """One connection's CRCL settings, as its commands set them (values as sent).

    Attributes:
        length_unit, angle_unit, force_unit, torque_unit: The units of its commands
            and statuses.
        joint_reports: What each joint's status says, by joint number, once a
            ``ConfigureJointReports`` set it (None: every joint's position, and its
            velocity while the arm moves).
        status_report: Which parts a full status carries (None: every part).
        gripper_enabled: ``DisableGripper`` turns SetEndEffector away until
            ``EnableGripper``.
    """

    length_unit: str = "meter"
    angle_unit: str = "radian"
    force_unit: str = "newton"
    torque_unit: str = "newtonMeter"
    trans_speed: TransSpeedAbsolute | TransSpeedRelative | None = None
    trans_accel: TransAccelAbsolute | TransAccelRelative | None = None
    rot_speed: RotSpeedAbsolute | RotSpeedRelative | None = None
    rot_accel: RotAccelAbsolute | RotAccelRelative | None = None
    end_pose_tolerance: PoseTolerance | None = None
    intermediate_pose_tolerance: PoseTolerance | None = None
    joint_tolerances: JointPositionsTolerances | None = None
    motion_coordinated: bool | None = None
    end_effector_parameters: tuple[ParameterSetting, ...] = ()
    joint_reports: dict[int, ConfigureJointReport] | None = None
    status_report: ConfigureStatusReport | None = None
    gripper_enabled: bool = True
    revision: int = 0
    """Bumped by every command that may have changed a setting (what statuses cache by)."""

    @property
    def length(self) -> float:
        """Meters per length unit."""
        return length_factor(self.length_unit)

    @property
    def angle(self) -> float:
        """Radians per angle unit."""
        return angle_factor(self.angle_unit)

    def joint_factors(self, prismatic: tuple[bool, ...]) -> list[float]:
        """SI per CRCL unit for each joint (length for prismatic, angle for revolute)."""
        return joint_factors(prismatic, self.length_unit, self.angle_unit)


def tidy(value: float) -> float:
    """``value`` to 12 significant digits, and 0 within 1e-12 of it: forward kinematics
    leaves noise such as ``0.499999999999986`` or ``1.0e-14`` where 0.5 and 0 are meant,
    far below what IK resolves (1e-9) or a robot shows."""
    return 0.0 if abs(value) < 1e-12 else float(f"{value:.12g}")


def pose_status(session: Session, settings: ConnectionSettings) -> PoseStatus:
    """The tool point's pose in the base frame, in the connection's length unit."""
    state = session.state
    placement = state.robot.ee_pose(session.now()) * state.tool
    pose = matrix_to_pose(placement.homogeneous, settings.length_unit)
    p, x, z = pose.point, pose.x_axis, pose.z_axis
    return PoseStatus(
        pose=Pose(
            Point(tidy(p.x), tidy(p.y), tidy(p.z)),
            Vector(tidy(x.i), tidy(x.j), tidy(x.k)),
            Vector(tidy(z.i), tidy(z.j), tidy(z.k)),
        )
    )


def joint_statuses(
    session: Session, settings: ConnectionSettings, configured_only: bool = False
) -> JointStatuses | None:
    """The joints' statuses as the connection's reports ask (None: none is reported, or
    ``configured_only`` and none was configured)."""
    reports = settings.joint_reports
    if reports is None and configured_only:
        return None
    factors = settings.joint_factors(session.robot.prismatic)
    q = session.world.faults.sensed(session.state.name, session.now())  # encoder noise, if on
    velocity = _velocity(session) if session.travel.active else None
    statuses = []
    for index, value in enumerate(q):
        number = index + 1
        report = reports.get(number) if reports is not None else None
        if reports is not None and report is None:
            continue
        position = report.report_position if report is not None else True
        speed = report.report_velocity if report is not None else velocity is not None
        if not (position or speed):
            continue
        v = (velocity[index] if velocity is not None else 0.0) / factors[index]
        statuses.append(
            JointStatus(
                joint_number=number,
                position=tidy(value / factors[index]) if position else None,
                velocity=tidy(v) if speed else None,
            )
        )
    return JointStatuses(tuple(statuses)) if statuses else None


def _velocity(session: Session) -> tuple[float, ...]:
    """Each joint's velocity now [rad/s or m/s]."""
    travel, clock = session.travel, session.world.clock
    t = clock.now()
    if travel.path is None:
        return travel.motion.sample(t)[1]
    now, before = travel.path.sample(t), travel.path.sample(t - _VELOCITY_DT_S)
    return tuple((a - b) / _VELOCITY_DT_S for a, b in zip(now, before))


def gripper_status(session: Session, settings: ConnectionSettings) -> ParallelGripperStatus | None:
    """The gripper's jaws apart, in the length unit (None: the robot has no gripper)."""
    state = session.state
    gripper = state.robot.gripper
    if gripper is None:
        return None
    opening = session.world.grips.now(state)
    return ParallelGripperStatus(
        gripper_name=gripper.name, separation=tidy(gripper.separation(opening) / settings.length)
    )


def settings_status(session: Session, settings: ConnectionSettings) -> SettingsStatus:
    """The settings in force: units, speeds (the set ones, else what moves use), the
    joints' limits and the tolerances, in the connection's units."""
    state, robot = session.state, session.robot
    length = settings.length
    factors = settings.joint_factors(robot.prismatic)
    velocity = session.world.motion_limits(state.name).velocity
    limits = tuple(
        JointLimit(
            joint_number=i + 1,
            min_position=robot.lower[i] / factors[i],
            max_position=robot.upper[i] / factors[i],
            max_velocity=float(velocity[i]) / factors[i],
        )
        for i in range(robot.n)
    )
    fraction = session.speed / 100.0
    return SettingsStatus(
        angle_unit=settings.angle_unit,
        end_effector_parameters=settings.end_effector_parameters,
        end_effector_setting=state.opening_target if robot.gripper is not None else None,
        force_unit=settings.force_unit,
        joint_limits=limits,
        intermediate_pose_tolerance=settings.intermediate_pose_tolerance,
        length_unit=settings.length_unit,
        motion_coordinated=settings.motion_coordinated,
        end_pose_tolerance=settings.end_pose_tolerance,
        rot_accel_absolute=_kind(settings.rot_accel, RotAccelAbsolute),
        rot_accel_relative=_kind(settings.rot_accel, RotAccelRelative),
        rot_speed_absolute=_kind(settings.rot_speed, RotSpeedAbsolute),
        rot_speed_relative=RotSpeedRelative(fraction),
        torque_unit=settings.torque_unit,
        trans_accel_absolute=_kind(settings.trans_accel, TransAccelAbsolute),
        trans_accel_relative=_kind(settings.trans_accel, TransAccelRelative),
        trans_speed_absolute=TransSpeedAbsolute(session.lspeed / length),
        trans_speed_relative=TransSpeedRelative(fraction),
        joint_tolerances=settings.joint_tolerances,
    )


def _kind(value: object, cls: type[T]) -> T | None:
    return value if isinstance(value, cls) else None


class StatusParts:
    """A connection's status parts, each built again only when what it shows changed:
    the arm at rest (or the gripper) stands where it stood, the settings did not move.
    A ``GetStatus`` while nothing moves then costs its parse and its writing."""

    def __init__(self, session: Session, settings: ConnectionSettings) -> None:
        self.session = session
        self.settings = settings
        self._memo: dict[str, tuple[object, object]] = {}
        self._texts: dict[str, tuple[object, str]] = {}

    def _memo_of(self, name: str, key: object, build: Callable[[], T]) -> T:
        held = self._memo.get(name)
        if key is not None and held is not None and held[0] == key:
            return held[1]  # type: ignore[return-value]
        value = build()
        self._memo[name] = (key, value)
        return value

    def _at_rest(self) -> object:
        """What the arm's parts depend on while it rests (None: it moves)."""
        session = self.session
        if session.travel.active or session.world.faults.any(session.state.name):
            return None  # (a fault's noise is drawn for each status)
        return (session.state.q, id(session.state.tool), self.settings.revision)

    def pose(self) -> PoseStatus:
        return self._memo_of(
            "pose", self._at_rest(), lambda: pose_status(self.session, self.settings)
        )

    def joints(self, configured_only: bool = False) -> JointStatuses | None:
        return self._memo_of(
            f"joints {configured_only}",
            self._at_rest(),
            lambda: joint_statuses(self.session, self.settings, configured_only),
        )

    def gripper(self) -> ParallelGripperStatus | None:
        session = self.session
        moving = session.world.grips.moving(session.state)
        key = None if moving else (session.state.opening, self.settings.revision)
        return self._memo_of("gripper", key, lambda: gripper_status(session, self.settings))

    def settings_status(self) -> SettingsStatus:
        session = self.session
        key = (
            self.settings.revision,
            session.speed,
            session.lspeed,
            session.state.opening_target,
        )
        return self._memo_of("settings", key, lambda: settings_status(session, self.settings))

    def write(self, status: CrclStatus) -> bytes:
        """``status.write_status(status)``, with each part that has not changed (the
        same record as last time) written from the text kept of it."""
        out = [XML_DECLARATION, f"<CRCLStatus{ROOT_ATTRIBUTES}>"]
        for part in _STATUS_PARTS:
            value = getattr(status, part.name)
            if value is None:
                continue
            held = self._texts.get(part.name)
            if held is not None and held[0] is value:
                out.append(held[1])
                continue
            piece: list[str] = []
            assert isinstance(part.codec, Nested)
            write_record(value, part.tag, piece, part.codec)
            text = "".join(piece)
            self._texts[part.name] = (value, text)
            out.append(text)
        out.append("</CRCLStatus>")
        return "".join(out).encode()
