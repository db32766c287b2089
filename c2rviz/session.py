"""One client's session: its unit mode and marker style, applied to the world.

This is the unit boundary. Clients speak degrees or radians (metres for
prismatic joints, always); everything past ``Session`` is SI. A command is
checked whole before anything changes, so a bad command never moves the robot
partly.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from operator import le, mul

import numpy as np
import pinocchio as pin

from . import replies
from .commands import (
    Clear,
    Color,
    Command,
    Help,
    Home,
    Joints,
    Limits,
    Mark,
    MarkerShape,
    Move,
    Names,
    Pose,
    Rand,
    Units,
    Where,
)
from .errors import JointCountError, JointIndexError, JointLimitError
from .robot import Robot
from .world import World

__all__ = ["Session", "UnitTable"]

_TOLERANCE = 1e-9  # relative slack at a limit, so a value read back with `where` is accepted


@dataclass(frozen=True, slots=True)
class UnitTable:
    """The chain's limits in one unit mode, and the factor from it to SI.

    Attributes:
        scale: Per joint, SI value = client value * scale.
        lower, upper: Limits in client units.
        unit: Per joint, ``deg``, ``rad`` or ``m``.
        angle_unit: ``deg`` or ``rad``, for poses.
    """

    scale: tuple[float, ...]
    lower: tuple[float, ...]
    upper: tuple[float, ...]
    unit: tuple[str, ...]
    angle_unit: str
    identity: bool = field(init=False)
    """Every scale is 1 (radians and metres): client values are SI values as they are."""

    def __post_init__(self) -> None:
        object.__setattr__(self, "identity", all(s == 1.0 for s in self.scale))

    @classmethod
    def build(cls, robot: Robot, degrees: bool) -> UnitTable:
        angle = math.pi / 180.0 if degrees else 1.0
        scale = tuple(1.0 if p else angle for p in robot.prismatic)
        angle_unit = "deg" if degrees else "rad"
        return cls(
            scale=scale,
            lower=tuple(lo / s for lo, s in zip(robot.lower, scale)),
            upper=tuple(hi / s for hi, s in zip(robot.upper, scale)),
            unit=tuple("m" if p else angle_unit for p in robot.prismatic),
            angle_unit=angle_unit,
        )


class Session:
    """Applies one client's commands to the shared world and returns reply lines."""

    def __init__(self, world: World) -> None:
        self.world = world
        self.robot = world.robot
        self._n = world.robot.n  # Robot.n is a property; this is read per command
        self._tables = (UnitTable.build(self.robot, False), UnitTable.build(self.robot, True))
        self.degrees = False
        self.table = self._tables[0]
        self.rgb: tuple[float, float, float] = (1.0, 0.0, 0.0)
        self.shape = "sphere"
        self._handlers: dict[type, Callable[[Command], str]] = {
            Rand: self._rand,
            Home: self._home,
            Units: self._units,
            Joints: self._joints,
            Move: self._move,
            Clear: self._clear,
            Mark: self._mark,
            Color: self._color,
            MarkerShape: self._marker_shape,
            Where: self._where,
            Pose: self._pose,
            Limits: self._limits,
            Names: self._names,
            Help: self._help,
        }

    def execute(self, command: Command) -> str:
        """Apply ``command``; return its ``ok`` reply or raise a ``C2rvizError``.

        Connection-level commands (``sleep``, ``bye``, ``quit``) belong to the
        server and are not accepted here.
        """
        handler = self._handlers.get(command.__class__)
        if handler is None:
            raise TypeError(f"{command!r} is not a world command")
        return handler(command)

    def to_si(self, indices: Sequence[int], values: Sequence[float]) -> list[float]:
        """Check ``values`` (client units) against the limits; return them in SI.

        Raises:
            JointLimitError: naming the first joint out of its limits.
        """
        table = self.table
        out = []
        for i, value in zip(indices, values):
            lower = table.lower[i]
            upper = table.upper[i]
            if lower <= value <= upper:
                out.append(value * table.scale[i])
            elif (
                lower - _TOLERANCE * max(1.0, abs(lower))
                <= value
                <= upper + _TOLERANCE * max(1.0, abs(upper))
            ):
                out.append(self.robot.lower[i] if value < lower else self.robot.upper[i])
            else:
                raise JointLimitError(
                    self.robot.joint_names[i], i, value, lower, upper, table.unit[i]
                )
        return out

    def from_si(self, values: Sequence[float]) -> list[float]:
        """Chain values in this client's units."""
        return [v / s for v, s in zip(values, self.table.scale)]

    # Handlers: each checks everything first, then changes the world.

    def _rand(self, command: Command) -> str:
        self.world.randomize()
        return replies.OK

    def _home(self, command: Command) -> str:
        self.world.home()
        return replies.OK

    def _units(self, command: Command) -> str:
        assert isinstance(command, Units)
        self.degrees = command.degrees
        self.table = self._tables[command.degrees]
        return replies.OK

    def _joints(self, command: Command) -> str:
        assert isinstance(command, Joints)
        values = command.values
        n = self._n
        if len(values) != n:
            raise JointCountError(n, len(values))
        table = self.table
        # The hot path (a stream of `joints` lines): all within limits, checked in C.
        if all(map(le, table.lower, values)) and all(map(le, values, table.upper)):
            self.world.set_q(values if table.identity else tuple(map(mul, values, table.scale)))
        else:
            self.world.set_q(self.to_si(range(n), values))
        return replies.OK

    def _move(self, command: Command) -> str:
        assert isinstance(command, Move)
        n = self._n
        for index in command.indices:
            if index >= n:
                raise JointIndexError(index, self.robot.name, n)
        q = list(self.world.q)
        for index, value in zip(command.indices, self.to_si(command.indices, command.values)):
            q[index] = value
        self.world.set_q(q)
        return replies.OK

    def _clear(self, command: Command) -> str:
        self.world.clear()
        return replies.OK

    def _mark(self, command: Command) -> str:
        assert isinstance(command, Mark)
        pose = None
        if command.pose is not None:
            x, y, z, roll, pitch, yaw = command.pose
            angle = math.pi / 180.0 if self.degrees else 1.0
            rotation = pin.rpy.rpyToMatrix(roll * angle, pitch * angle, yaw * angle)
            pose = pin.SE3(rotation, np.array([x, y, z]))
        self.world.add_marker(pose, self.rgb, self.shape)
        return replies.OK

    def _color(self, command: Command) -> str:
        assert isinstance(command, Color)
        self.rgb = command.rgb
        return replies.OK

    def _marker_shape(self, command: Command) -> str:
        assert isinstance(command, MarkerShape)
        self.shape = command.shape
        return replies.OK

    def _where(self, command: Command) -> str:
        return replies.ok(replies.numbers(self.from_si(self.world.q)))

    def _pose(self, command: Command) -> str:
        pose = self.world.ee_pose()
        angle = 180.0 / math.pi if self.degrees else 1.0
        rpy = pin.rpy.matrixToRpy(pose.rotation) * angle
        return replies.ok(replies.numbers([*pose.translation, *rpy]))

    def _limits(self, command: Command) -> str:
        table = self.table
        return replies.ok(
            ",".join(
                f"{replies.numbers([lo])}..{replies.numbers([hi])} {unit}"
                for lo, hi, unit in zip(table.lower, table.upper, table.unit)
            )
        )

    def _names(self, command: Command) -> str:
        return replies.ok(f"{self.robot.name} {','.join(self.robot.joint_names)}")

    def _help(self, command: Command) -> str:
        return replies.HELP
