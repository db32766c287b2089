"""What ROS clients send to move the robot: text command lines, joint positions, trajectories.

Text command lines: one ``Session`` per client and robot, in order. A line published
on ``[NS]/c2rviz/command`` or sent to the service of that name runs through the
session of its client (``rosbridge HOST:PORT``) for that robot, exactly as a line on
the text port: parsed, checked, guarded, noted in the world's commands. The session
keeps its modes (``degrees``, ``motion on``, ``speed``...) between lines, as a TCP
connection's does. Lines run in the order they came, each after the previous one's
reply (a reply may wait: ``sleep``, a move with ``motion on``), while the client's
other requests go on. At most ``MAX_WAITING`` lines wait behind a reply; one more is
refused. A line that runs at once (nothing before it waits) and is refused raises, so
the publishing client gets a ``status`` error as well. ``bye`` starts the session
afresh (the websocket stays open); ``quit`` stops the program, as on the text port.

Joint positions and trajectories, checked whole and run on a ``Session``. A
``sensor_msgs/msg/JointState`` on ``[NS]/joint_command`` is a move like ``move``: the
named chain joints go to their positions [rad or m] (the others keep their target),
through ``Session.set_joints`` (the session's motion mode, speed and guard apply). A
``trajectory_msgs/msg/JointTrajectory`` on ``[NS]/joint_trajectory`` is timed motion: it
starts now from where the arm is (which must be at rest), passes each point at its
``time_from_start`` and is played on the world's clock (``Session.play_trajectory``);
chain joints it does not name hold still. It is refused whole if any point or any
instant between breaks a position, velocity or acceleration limit (the robot's motion
limits at full speed, whatever the session's ``speed``), or, with ``guard on``, if any
instant of it collides. The session tells the world of either (``Session.said``: the
page's "last commands", its last error, recordings) as ``/joint_command
joint_s=0.5,...`` or ``/joint_trajectory N points, T s``, taken or refused. Units are SI
whatever the session's ``degrees``.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
from collections import deque
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import partial

import numpy as np

from ...errors import ArmMoved, C2rvizError, JointLimitError, within_limit
from ...motion.trajectory import PlannedTrajectory, plan_trajectory
from ...protocol import replies
from ...protocol.registry import Reply
from ...robot.model import Robot
from ...session.calls import MAX_TRAJECTORY_CHECKS
from ...session.services import Services
from ...session.session import Session
from .messages import JointPositions, JointTrajectory, TrajectoryOutline

# Text command lines.

log = logging.getLogger("c2rviz.rosbridge")

MAX_WAITING = 100
"""Lines of one client and robot that may wait behind a reply."""

Answer = Callable[[str, bool], None]
"""Takes a line's reply text and whether it was not an error."""


class CommandRefused(C2rvizError):
    """A line refused at once: its reply's problem."""


@dataclass(eq=False)
class _Waiting:
    line: str
    answer: Answer


class LineQueue:
    """The lines of one client for one robot, run in order through its session."""

    def __init__(self, make_session: Callable[[], Session], on_quit: Callable[[], None]) -> None:
        self.make_session = make_session
        self.session = make_session()
        self.on_quit = on_quit
        self._waiting: deque[_Waiting] = deque()
        self._task: asyncio.Task[None] | None = None

    @property
    def busy(self) -> bool:
        """A reply is awaited, or lines wait."""
        return self._task is not None

    def take(self, line: str, answer: Answer) -> None:
        """Run ``line`` now if nothing waits, else after the lines before it.

        Raises:
            CommandRefused: The line ran at once and was refused (``answer`` was told too).
            C2rvizError: ``MAX_WAITING`` lines wait already.
        """
        if self._task is None:
            reply = self._run(line)
            if reply is None or isinstance(reply, str):
                self._finish(reply, answer)
                if reply is not None and reply.startswith("error:"):
                    raise CommandRefused(reply.removeprefix("error: "))
                return
            self._task = asyncio.ensure_future(self._await_then_drain(reply, answer))
            return
        if len(self._waiting) >= MAX_WAITING:
            raise C2rvizError(
                f"too many commands waiting behind a reply (limit {MAX_WAITING}); "
                "wait for /c2rviz/reply or send stop"
            )
        self._waiting.append(_Waiting(line, answer))

    async def ask(self, line: str) -> tuple[str, bool]:
        """Run ``line`` in its turn and return its reply text and whether it is not an error."""
        done: asyncio.Future[tuple[str, bool]] = asyncio.get_running_loop().create_future()

        def answer(text: str, ok: bool) -> None:
            if not done.done():
                done.set_result((text, ok))

        with contextlib.suppress(CommandRefused):  # answered already
            self.take(line, answer)
        return await done

    def close(self) -> None:
        """The client is gone: lines still waiting are dropped, a reply waited for too."""
        self._waiting.clear()
        if self._task is not None:
            self._task.cancel()

    def _run(self, line: str) -> Reply | None:
        try:
            return self.session.run(line)
        except C2rvizError as error:
            return replies.error(error)
        except Exception:  # a bug must cost one reply, never the door
            log.exception("rosbridge: internal error on %r from %s", line, self.session.source)
            return replies.error("internal error (see the server log)")

    def _finish(self, reply: str | None, answer: Answer) -> None:
        if reply is None:  # a blank or comment line: no reply, as on the text port
            answer("", True)
            return
        hangup = self.session.take_hangup()
        answer(reply, not reply.startswith("error:"))
        if hangup == "bye":
            self.session = self.make_session()
        elif hangup == "quit":
            self.on_quit()

    async def _await_then_drain(self, reply: Reply, answer: Answer) -> None:
        try:
            self._finish(await _settled(reply), answer)
            while self._waiting:
                item = self._waiting.popleft()
                now = self._run(item.line)
                if now is not None and not isinstance(now, str):
                    now = await _settled(now)
                self._finish(now, item.answer)
        finally:
            self._task = None


async def _settled(reply: Reply) -> str:
    """The text of a reply that waits (an error's text when it fails)."""
    try:
        return reply if isinstance(reply, str) else await reply
    except C2rvizError as error:
        return replies.error(error)
    except asyncio.CancelledError:
        raise
    except Exception:  # a bug must cost one reply, never the door
        log.exception("rosbridge: internal error while a reply was awaited")
        return replies.error("internal error (see the server log)")


class CommandLines:
    """Every client's line queues, by client and robot."""

    def __init__(self, services: Services, on_quit: Callable[[], None]) -> None:
        self.services = services
        self.on_quit = on_quit
        self.queues: dict[tuple[str, str], LineQueue] = {}

    def queue(self, source: str, robot: str) -> LineQueue:
        """The queue (and session) of ``source`` for ``robot``."""
        key = (source, robot)
        queue = self.queues.get(key)
        if queue is None:
            queue = self.queues[key] = LineQueue(
                partial(Session, self.services, source, robot), self.on_quit
            )
        return queue

    def session(self, source: str, robot: str) -> Session:
        """The session of ``source`` for ``robot`` (its joint inputs use its modes)."""
        return self.queue(source, robot).session

    def closed(self, source: str) -> None:
        """The client ``source`` is gone: drop its sessions."""
        for key in [k for k in self.queues if k[0] == source]:
            self.queues.pop(key).close()


# Joint positions and trajectories.

MAX_GUARD_SAMPLES = MAX_TRAJECTORY_CHECKS
"""Most instants of a trajectory checked for collisions (one per frame, or fewer)."""
ROWS = 500
"""Points' numbers turned into an array in one call at most: numpy holds the interpreter's
lock through it (some 0.3 ms a slice), and the worker thread hands the lock to the event
loop only between calls."""


class UnknownJointName(C2rvizError):
    """A joint name that is not one of the robot's chain joints."""

    def __init__(self, field: str, name: str, robot: Robot, robot_name: str) -> None:
        self.field, self.name = field, name
        shown = name if len(name) <= 60 else name[:60] + "..."
        super().__init__(
            f"{field}: {shown!r} is not a joint of {robot_name}'s chain "
            f"{robot.base} -> {robot.eelink} (its joints: {', '.join(robot.joint_names)})"
        )


def _indices(session: Session, field: str, names: Sequence[str]) -> list[int]:
    index = {name: i for i, name in enumerate(session.robot.joint_names)}
    out = []
    for k, name in enumerate(names):
        if name not in index:
            raise UnknownJointName(f"{field}[{k}]", name, session.robot, session.state.name)
        out.append(index[name])
    return out


def _units(robot: Robot) -> list[str]:
    return ["m" if prismatic else "rad" for prismatic in robot.prismatic]


def joint_command(session: Session, command: JointPositions) -> None:
    """Send the named joints to their positions now (or travelling, as the session moves).

    Raises:
        UnknownJointName: A name that is not a chain joint.
        JointLimitError: A position outside its joint's limits.
        PathCollides: With ``guard on``, the target or the way there collides.
    """
    said = session.said(
        "/joint_command "
        + ",".join(
            f"{name}={replies.numbers([value])}"
            for name, value in zip(command.names, command.positions)
        )
    )
    try:
        robot = session.robot
        q = list(session.state.target)
        units = _units(robot)
        for i, value in zip(_indices(session, "name", command.names), command.positions):
            lower, upper = robot.lower[i], robot.upper[i]
            if not within_limit(value, lower, upper):
                raise JointLimitError(robot.joint_names[i], i, value, lower, upper, units[i])
            q[i] = min(max(value, lower), upper)
    except C2rvizError as error:
        said.refuse(error)
        raise
    session.set_joints(q, said=said)  # motion on: nobody waits for the arrival


async def joint_trajectory(
    session: Session, trajectory: JointTrajectory | TrajectoryOutline
) -> None:
    """Check ``trajectory`` whole, then play it from now on the world's clock. Its plan,
    its limit check and (``guard on``) its collision check run off the event loop, on the
    session's worker: a trajectory of thousands of points stalls no other client. Its
    outline (a large one, found naming a joint the robot lacks as it was decoded) is
    refused as the trajectory would be.

    Raises:
        UnknownJointName: A name that is not a chain joint.
        ArmMoved: The arm is moving (a trajectory starts from rest), or it moved (another
            door drives it) while the trajectory was checked.
        TrajectoryError: A point or an instant between points breaks a limit.
        PathCollides: With ``guard on``, an instant of it collides.
    """
    shown = TrajectoryOutline.of(trajectory)
    said = session.said(f"/joint_trajectory {shown.point_count} points, {shown.duration_s:g} s")
    try:
        start, planned = await session.unstopped(_checked(session, trajectory))
        _at_rest(session, start)  # (another door may have moved it meanwhile)
    except C2rvizError as error:
        said.refuse(error)
        raise
    session.play_trajectory(planned, checked=True, said=said)


def _at_rest(session: Session, start: np.ndarray | None = None) -> None:
    """A trajectory starts from rest (at ``start``, where it was planned from)."""
    if session.travel.active or (start is not None and not np.array_equal(session.state.q, start)):
        raise ArmMoved(
            "a trajectory starts from rest and the arm is moving: send stop (or wait) first"
        )


async def _checked(
    session: Session, trajectory: JointTrajectory | TrajectoryOutline
) -> tuple[np.ndarray, PlannedTrajectory]:
    """``_plan``, then the guard's check of what it planned."""
    start, planned = await _plan(session, trajectory)
    await session.check_trajectory(planned)
    return start, planned


async def _plan(
    session: Session, trajectory: JointTrajectory | TrajectoryOutline
) -> tuple[np.ndarray, PlannedTrajectory]:
    """Where the arm starts, and the trajectory planned and checked against the limits
    from there on the session's worker."""
    indices = _indices(session, "joint_names", trajectory.joint_names)
    if isinstance(trajectory, TrajectoryOutline):  # (read against other joints: never here)
        raise C2rvizError("joint_names: the trajectory was read for another chain; send it again")
    _at_rest(session)
    robot, state, world = session.robot, session.state, session.world
    start = np.asarray(state.q, dtype=float)
    zeros = np.zeros(robot.n)
    limits = world.motion_limits(state.name)

    def chain(rows: Sequence[Sequence[float]], base: np.ndarray) -> np.ndarray:
        full = np.tile(base, (len(rows), 1))
        for first in range(0, len(rows), ROWS):  # (the loop may take the lock between)
            full[first : first + ROWS, indices] = rows[first : first + ROWS]
        return full

    def given(rows: list[Sequence[float] | None]) -> list[np.ndarray | None]:
        if rows.count(None) == len(rows):
            return [None] * len(rows)
        present = chain([row for row in rows if row is not None], zeros)
        each = iter(present)
        return [None if row is None else next(each) for row in rows]

    def plan() -> PlannedTrajectory:  # arrays built whole: few Python steps per point
        points = trajectory.points
        return plan_trajectory(
            start,
            [p.time_from_start_s for p in points],
            chain([p.positions for p in points], start),
            given([p.velocities for p in points]),
            given([p.accelerations for p in points]),
            limits,
            robot.joint_names,
            _units(robot),
        )

    return start, await session.services.worker.run(plan, owner=session)
