# Written by scripts/unasync_clients.py from c2rviz/clients/aio_verbs.py: do not edit;
# edit aio_verbs.py, then run `python scripts/unasync_clients.py`.
"""``Client``'s verbs (``Verbs``), the blocking twins of ``aio_verbs.AsyncVerbs``."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, TypeVar

from ..protocol.registry import VERBS
from . import calls, records, task_calls
from .calls import Call, speaks
from .records import (
    JointLimit,
    MotionLimit,
    MotionStatus,
    Pose,
    RobotNames,
    VersionInfo,
)
from .task_calls import PlanSummary

T = TypeVar("T")


class Verbs:
    """The robot's verbs: joints, questions, the connection, the tool point, motion, cells
    and planning (a part of the client; its ``call`` sends, its ``close`` closes)."""

    robot_name: str | None
    _names: tuple[str, ...] | None

    def call(self, call: Call[T]) -> T:
        raise NotImplementedError  # the client's

    def close(self) -> None:
        raise NotImplementedError  # the client's

    def send(self, line: str) -> str:
        raise NotImplementedError  # the client's

    if not TYPE_CHECKING:  # a type checker sees the typed methods alone

        def __getattr__(self, name: str):
            """A verb of the registry with no typed method (yet): ``client.VERB(*words)``
            sends ``VERB words...`` (each word as ``str`` gives it) and returns the ``ok``
            reply as it came (``CommandError`` for an ``error:``), as ``send`` does."""
            if name.startswith("_") or name not in VERBS:
                raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")

            def send_verb(*words: object) -> str:
                return self.send(" ".join([name, *map(str, words)]))

            send_verb.__name__ = send_verb.__qualname__ = name
            return send_verb

    # The joints.

    @speaks("joints")
    def joints(self, values: Sequence[float]) -> None:
        """Set all chain joints [rad, or deg; m for a prismatic joint]: at once (``motion
        off``), or travelling (``on``: returns on arrival; ``follow``: at once)."""
        return self.call(calls.joints(values))

    @speaks("move")
    def move(self, indices: Sequence[int] | int, values: Sequence[float]) -> None:
        """Set the joints at ``indices`` to ``values`` [rad, or deg; m], the rest stay."""
        return self.call(calls.move(indices, values))

    @speaks("home")
    def home(self) -> None:
        """Every chain joint to 0 (or its nearest limit)."""
        return self.call(calls.HOME)

    @speaks("rand")
    def rand(self) -> None:
        """Every chain joint to a random value within its limits (free, with the guard)."""
        return self.call(calls.RAND)

    @speaks("degrees")
    def degrees(self) -> None:
        """Angles of this connection in degrees from now on, both ways."""
        return self.call(calls.DEGREES)

    @speaks("radians")
    def radians(self) -> None:
        """Angles of this connection in radians from now on (the default)."""
        return self.call(calls.RADIANS)

    # Questions.

    @speaks("where")
    def where(self) -> tuple[float, ...]:
        """The chain's joint values now [rad, or deg; m] (mid-move too)."""
        return self.call(calls.WHERE)

    @speaks("pose")
    def pose(self) -> Pose:
        """The tool pose in the base frame: x, y, z [m], roll, pitch, yaw [rad, or deg]."""
        return self.call(calls.POSE)

    @speaks("limits")
    def limits(self) -> list[JointLimit]:
        """Each chain joint's range [rad, or deg; m] and unit, in index order."""
        return self.call(calls.LIMITS)

    @speaks("limits")
    def motion_limits(self) -> list[MotionLimit]:
        """Each chain joint's velocity, acceleration and jerk limits [rad, or deg; m per s,
        s^2, s^3] (``limits all``)."""
        return self.call(calls.MOTION_LIMITS)

    @speaks("names")
    def names(self) -> RobotNames:
        """The robot this connection drives and its chain's joint names, in index order."""
        names = self.call(calls.NAMES)
        self.robot_name, self._names = names  # what a joint count is checked against
        return names

    @speaks("version")
    def version(self) -> VersionInfo:
        """The server's version and the robot file it loaded."""
        return self.call(calls.VERSION)

    @speaks("help")
    def help(self) -> list[str]:
        """Every verb's usage, as the server lists them."""
        return self.call(calls.HELP)

    # The connection.

    @speaks("sleep")
    def sleep(self, seconds: float) -> None:
        """Pause this connection for ``seconds`` [s of the server's clock] (others go on)."""
        return self.call(calls.sleep(seconds))

    @speaks("bye")
    def bye(self) -> None:
        """Close this connection politely (a later call reconnects)."""
        self.call(calls.BYE)
        self.close()

    @speaks("quit")
    def quit(self) -> None:
        """Stop the server (command server and viewer); this connection closes."""
        self.call(calls.QUIT)
        self.close()

    # The tool point.

    @speaks("tool")
    def tool(self, pose: Sequence[float] | None = None) -> Pose:
        """Set the tool point relative to the end-effector link (x, y, z [m], roll, pitch,
        yaw [rad, or deg]) for every connection; return it (without ``pose``: as it is)."""
        return self.call(calls.tool(pose))

    @speaks("ik")
    def ik(self, pose: Sequence[float]) -> tuple[float, ...]:
        """Joint values [rad, or deg; m] that put the tool point at ``pose`` (x, y, z [m],
        roll, pitch, yaw [rad, or deg]); nothing moves."""
        return self.call(calls.ik(pose))

    @speaks("moveto")
    def moveto(self, pose: Sequence[float] | None = None, *, marker: int | None = None) -> None:
        """Go to a tool pose (x, y, z [m], roll, pitch, yaw [rad, or deg]) through joint
        space, or to marker N's pose (1: the oldest)."""
        return self.call(calls.moveto(pose, marker))

    @speaks("movel")
    def movel(self, pose: Sequence[float]) -> None:
        """The tool point travels a straight line to ``pose`` (x, y, z [m], roll, pitch,
        yaw [rad, or deg]) at this connection's ``lspeed``."""
        return self.call(calls.movel(pose))

    @speaks("lspeed")
    def lspeed(self, m_s: float | None = None) -> float:
        """Set ``movel``'s tool speed [m/s] (0 < V <= 5); return it (without one: as it is)."""
        return float(self.call(calls.setting("lspeed", "m_s", m_s, records.read_number)))

    # Motion.

    @speaks("motion")
    def motion(self, mode: str | None = None) -> str:
        """Set how this connection's moves travel: ``off`` (at once), ``on`` (the call
        returns on arrival) or ``follow`` (travel, return at once); return the mode."""
        return self.call(calls.motion(mode))

    @speaks("speed")
    def speed(self, percent: float | None = None) -> float:
        """Set this connection's moves to ``percent`` [% of the joints' limits, 1..100];
        return it (without one: as it is)."""
        return float(self.call(calls.setting("speed", "percent", percent, records.read_number)))

    @speaks("stop")
    def stop(self) -> None:
        """Bring the arm to rest within its limits; returns when it is."""
        return self.call(calls.STOP)

    @speaks("wait")
    def wait(self) -> None:
        """Return when the arm is at rest."""
        return self.call(calls.WAIT)

    @speaks("target")
    def target(self) -> tuple[float, ...]:
        """The joint values the arm is moving to, or stands at [rad, or deg; m]."""
        return self.call(calls.TARGET)

    @speaks("status")
    def status(self) -> MotionStatus:
        """Whether the arm moves, and the seconds until it is at rest [s of the server's clock]."""
        return self.call(calls.STATUS)

    # Cells.

    @speaks("robot")
    def robot(self, name: str | None = None) -> str:
        """Drive robot ``name`` of the cell from now on; return the robot driven."""
        return self.call(calls.robot(name))

    @speaks("robots")
    def robots(self) -> dict[str, int | None]:
        """The cell's robots and their command ports."""
        return self.call(calls.ROBOTS)

    # Planning, the guard's modes, the gripper and the ghost.

    @speaks("plan")
    def plan_joints(self, values: Sequence[float]) -> PlanSummary:
        """A collision-free path to joint ``values`` [rad, or deg; m]; with motion on, the
        arm moves along it (the reply comes as ``motion`` says)."""
        return self.call(task_calls.plan_joints(values))

    @speaks("plan")
    def plan_pose(self, pose: Sequence[float]) -> PlanSummary:
        """A collision-free path to a tool ``pose`` (x, y, z [m], and roll, pitch, yaw
        [rad, or deg], or the position alone); moves as ``plan_joints``."""
        return self.call(task_calls.plan_pose(pose))

    @speaks("plan")
    def plan(self) -> list[tuple[float, ...]]:
        """The last planned path's waypoints, each the chain's joint values [rad, or deg; m]."""
        return self.call(task_calls.PLAN)

    @speaks("plan")
    def plan_timeout(self, seconds: float | None = None) -> float:
        """Set (or with None, return) this connection's planning time limit [s]."""
        return self.call(task_calls.plan_timeout(seconds))

    @speaks("plan")
    def plan_resolution(self, steps: Sequence[float] | None = None) -> tuple[float, ...]:
        """Set (or with None, return) the checks' steps: (a joint's angle [rad, or deg],
        the tool's travel [m])."""
        return self.call(task_calls.plan_resolution(steps))

    @speaks("guard")
    def guard_mode(self, mode: str | None = None) -> str:
        """The guard as ``on``, ``off`` or ``plan`` (a refused move is planned around);
        returns it."""
        return self.call(task_calls.guard_mode(mode))

    @speaks("grip")
    def grip(self, opening: float | None = None) -> float:
        """The gripper to ``opening`` [0 closed .. 1 open] (arrives as ``motion`` says), or
        with None return its opening; returns the opening."""
        return self.call(task_calls.grip(opening))

    @speaks("ghost")
    def ghost(self, on: bool | None = None) -> bool:
        """Show this connection's targets and paths as a ghost on the page (``True``, the
        default); returns whether it does."""
        return self.call(task_calls.ghost(on))

    # Faults on demand (docs/faults.md).

    @speaks("fault")
    def fault(
        self, kind: str, *args: float | str, at: float | None = None, after: float | None = None
    ) -> None:
        """Make a fault happen on this robot: now, at the server's clock time ``at`` [s] or
        ``after`` [s] from now. ``fault("estop")``, ``fault("stall", "joint_l")``,
        ``fault("noise", 0.01)`` [rad, or deg], ``fault("latency", 50, 10)`` [ms]."""
        return self.call(task_calls.fault(kind, args, at, after))

    @speaks("fault")
    def clear_faults(self, kind: str = "all") -> None:
        """End this robot's faults of ``kind`` (``all``: every one, scheduled ones too)."""
        return self.call(task_calls.clear_faults(kind))

    @speaks("faults")
    def faults(self) -> list[str]:
        """This robot's faults: ``estop since 1.500``, ``noise 0.01 at 5.000`` [s]..."""
        return self.call(task_calls.FAULTS)

    @speaks("reset")
    def reset(self) -> None:
        """Lift a stop (a protective one, or an emergency stop already cleared)."""
        return self.call(task_calls.RESET)
