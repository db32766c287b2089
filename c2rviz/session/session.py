"""One source's session: its robot, unit mode and marker style — the one way in.

Every change of the world comes through a ``Session``: a TCP connection has
one, so does the page, so does a replay. ``run(line)`` parses a line and
executes it; ``execute(command)`` runs an already parsed one through its
handler (``registry.HANDLERS``). This is the unit boundary: sources speak
degrees or radians (metres for prismatic joints, always); everything past the
session is SI. A handler checks a command whole before the world changes, so a
bad command never moves the robot partly.
"""

from __future__ import annotations

import asyncio
import functools
import math
from collections.abc import Sequence

import numpy as np
import pinocchio as pin

from ..errors import C2rvizError, JointLimitError, MotionInterrupted, PathCollides
from ..planning import EdgeResolution, MoveChecker, edge_resolution, first_blocked, path_points
from ..protocol import replies
from ..protocol.grammar import ForeignProtocol, numbers_batch, parse_line
from ..protocol.registry import HANDLERS, Reply
from ..robot.frames import pose_se3, se3_pose
from ..tolerance import within_limit
from ..world.moves import Travel
from ..world.state import RobotState
from .guarded import guarded_go, request
from .services import Services
from .units import UnitTable

__all__ = ["Session", "UnitTable"]

_CADENCE_S = 0.02  # a pause this soon after the previous one's end continues its cadence


class Session:
    """Applies one source's commands to the shared world.

    Attributes:
        source: Who speaks (``tcp 127.0.0.1:5123``, ``page``), for notes and errors.
        motion: ``off``, ``on`` or ``follow`` (``protocol.verbs.motion.MOTION_MODES``).
        speed: Moves at this % of the joints' limits.
        guard: Refuse commands whose target or path collides.
        plan_around: With the guard, plan joint-space moves around what their straight
            path would hit (``guard plan``).
        lspeed: ``movel``'s tool speed [m/s].
        plan_timeout_s: Most time a plan searches [s].
        plan_seed: The planner's seed (None: a fresh one each plan).
        last_plan: The waypoints of the last path ``plan`` found [rad or m], if any.
        hangup: Set by a handler to ``"bye"`` or ``"quit"``: the connection closes
            after this reply (and for ``quit`` stops the program).
    """

    def __init__(self, services: Services, source: str = "tcp", robot: str | None = None) -> None:
        """A session of ``source`` driving ``robot`` (None: the world's default robot)."""
        self.services = services
        self.world = services.world
        self.source = source
        self.limits = services.limits
        self.degrees = False
        self.rgb: tuple[float, float, float] = (1.0, 0.0, 0.0)
        self.shape = "sphere"
        self.hangup: str | None = None
        self._pause_end = -math.inf  # when the latest `after` was due [clock s]
        defaults = services.defaults
        self.motion = defaults.motion
        self.speed = defaults.speed
        self.guard = defaults.guard
        self.plan_around = defaults.guard and defaults.plan_around
        self.lspeed = defaults.lspeed
        self.plan_timeout_s = defaults.plan_timeout_s
        self.plan_seed = defaults.plan_seed
        self.last_plan: np.ndarray | None = None
        self._steps = (defaults.plan_step_rad, defaults.plan_tool_step_m)
        self.select(robot)

    def select(self, name: str | None) -> None:
        """Drive robot ``name`` from now on (None: the world's default robot).

        Raises:
            UnknownRobot: naming the robots there are; nothing changes.
        """
        self.state: RobotState = self.world.state(name)
        self.travel: Travel = self.world.travel(self.state.name)
        self.robot = self.state.robot
        self.n = self.robot.n  # Robot.n is a property; this is read per command
        self._tables = (UnitTable.build(self.robot, False), UnitTable.build(self.robot, True))
        self.table = self._tables[self.degrees]
        self.last_plan = None
        self._resolution: EdgeResolution | None = None

    @property
    def resolution(self) -> EdgeResolution:
        """How finely this session's guarded paths and plans are checked."""
        if self._resolution is None:
            step_rad, tool_m = self._steps
            self._resolution = edge_resolution(self.robot, step_rad, max_tool_step_m=tool_m)
        return self._resolution

    @property
    def steps(self) -> tuple[float, float | None]:
        """The resolution's revolute step [rad] and tool step [m] (None: no tool bound)."""
        return self._steps

    def set_steps(self, step_rad: float, tool_step_m: float | None) -> None:
        """Check paths at these steps from now on.

        Raises:
            BadPlanningSetting: a step that is NaN, <= 0 or too large (names the range).
        """
        edge_resolution(self.robot, step_rad, max_tool_step_m=tool_step_m)  # checks them
        self._steps = (step_rad, tool_step_m)
        self._resolution = None

    def go(self, q: Sequence[float]) -> Reply:
        """Send this session's robot to ``q`` [rad or m, checked]: at once (``motion off``),
        or travelling (``on``: the reply comes on arrival; ``follow``: ``ok`` now).

        With the guard, the move is checked (or planned around, ``guard plan``) off the
        event loop and played on the checked path (``guarded.guarded_go``): the reply
        is then always awaitable."""
        if self.guard:
            return guarded_go(self, [q], self.speed)
        if self.motion == "off":
            self.world.set_q(q, self.state.name, self.source)
            return replies.OK
        arrival = self.world.travels.go(
            self.state, q, self.speed / 100.0, self.source, wait=self.motion == "on"
        )
        return replies.OK if arrival is None else arrival

    def check_path(self, q: Sequence[float], path: Sequence[Sequence[float]] = ()) -> None:
        """Refuse ``q`` if it collides, or if any point of the way there does (``path``,
        else the straight joint-space segment from where the arm is now): with itself,
        its objects, and the other robots of the world as they stand. Contacts where
        the arm is now may be left, not pushed into (``planning.first_blocked``).

        This checks on the event loop; moves sent through ``go`` are checked off it.

        Raises:
            PathCollides: naming the pair and how far along the move.
        """
        at_target = self.motion == "off" and not path
        start = self.now()
        asked = request(self, start, [q])
        checker = MoveChecker().checker(asked)
        allowed = checker.batch.colliding(start)
        if at_target:
            points = np.array([q], dtype=float)
        else:
            waypoints = np.array(path if path else [start, q], dtype=float)
            points = path_points(checker, waypoints)
        found = first_blocked(checker, points, allowed)
        if found is not None:
            index, (first, second) = found
            fraction = index / max(len(points) - 1, 1)
            raise PathCollides(first, second, fraction, at_target, target=q)

    def joints_run(self, texts: Sequence[str]) -> bool:
        """A run of ``joints`` lines (their value lists) checked as one: with ``motion off``
        and no guard, if every line has n values within the limits, only the last is
        applied (the ones before would be shown for no time at all) and True is returned;
        else False, and nothing changed: the lines are then run one by one, so every
        reply and error is exactly as if they had been."""
        if self.motion != "off" or self.guard or self.world.faults.any(self.state.name):
            return False
        flat = numbers_batch(texts, self.n)
        table = self.table
        if flat is None or not table.within(flat):
            return False
        self.world.set_q(table.to_si(flat[-self.n :]), self.state.name, self.source)
        return True

    def now(self) -> tuple[float, ...]:
        """The robot's joints at this instant [rad or m] (mid-move too)."""
        return self.world.travels.now(self.state) if self.travel.active else self.state.q

    def set_degrees(self, degrees: bool) -> None:
        self.degrees = degrees
        self.table = self._tables[degrees]

    @property
    def angle_scale(self) -> float:
        """SI angle = client angle * this (for poses)."""
        return math.pi / 180.0 if self.degrees else 1.0

    def execute(self, command: object) -> Reply:
        """Run ``command``; return its reply (or an awaitable of it), or raise a
        ``C2rvizError`` having changed nothing."""
        return HANDLERS[command.__class__](self, command)

    def run(self, line: str) -> Reply | None:
        """Parse and run one line (None for a blank or comment line), noting it in the
        world as accepted or refused, and its reply once known (``World.replied``: a reply
        that waits is handed back as a future that notes it when it comes)."""
        world = self.world
        try:
            command = parse_line(line)
            if command is None:
                return None
            reply = HANDLERS[command.__class__](self, command)
            if world.faults.late and self.hangup is None:  # latency: the reply comes late
                reply = world.faults.delayed(self.state.name, reply)
        except C2rvizError as exc:
            world.note(self.source, line, False)
            world.refused(self.state.name, self.source, line, exc)
            if not isinstance(exc, ForeignProtocol):  # a door answers that one its own way
                world.replied(self.source, line, replies.error(exc))
            raise
        world.note(self.source, line, True)
        if isinstance(reply, str):
            world.replied(self.source, line, reply)
            return reply
        later = asyncio.ensure_future(reply)
        later.add_done_callback(functools.partial(self._replied, self.state.name, line))
        return later

    def _replied(self, robot: str, line: str, later: asyncio.Future[str]) -> None:
        """A reply that waited has come (one cancelled never reached anyone): the world
        hears it, and a refusal (not a preemption) as a refusal."""
        if later.cancelled():
            return
        error = later.exception()
        if error is None:
            text = later.result()
        elif isinstance(error, C2rvizError):
            text = replies.error(error)
            if not isinstance(error, MotionInterrupted):
                self.world.refused(robot, self.source, line, error)
        else:
            text = replies.error("internal error (see the server log)")
        self.world.replied(self.source, line, text)

    def after(self, seconds: float, reply: str) -> asyncio.Future[str]:
        """A reply that comes ``seconds`` [s] from now (on the running loop).

        A pause that follows the previous one at once (within ``_CADENCE_S``: the
        source went straight on, as a played script does between ``sleep`` lines)
        counts from that one's end, so a timer that fires a little late does not
        make a replay drift: ``sleep`` keeps a script's cadence.
        """
        clock = self.world.clock
        now = clock.now()
        start = self._pause_end if 0.0 <= now - self._pause_end <= _CADENCE_S else now
        self._pause_end = start + seconds
        future: asyncio.Future[str] = clock.future()  # a reply that waits on the clock
        timer = clock.call_at(self._pause_end, _settle, future, reply)
        future.add_done_callback(lambda _: timer.cancel())
        return future

    # The unit boundary.

    def pose_se3(self, pose: Sequence[float]) -> pin.SE3:
        """A pose as this source writes it (x, y, z [m]; roll, pitch, yaw in its angle unit)
        as a placement."""
        x, y, z, roll, pitch, yaw = pose
        angle = self.angle_scale
        return pose_se3((x, y, z, roll * angle, pitch * angle, yaw * angle))

    def pose_text(self, placement: pin.SE3) -> str:
        """A placement as this source reads a pose: ``x,y,z,roll,pitch,yaw`` in its units."""
        x, y, z, roll, pitch, yaw = se3_pose(placement)
        angle = self.angle_scale
        return replies.numbers([x, y, z, roll / angle, pitch / angle, yaw / angle])

    def to_si(self, indices: Sequence[int], values: Sequence[float]) -> list[float]:
        """Check ``values`` (client units) against the limits; return them in SI.

        Raises:
            JointLimitError: naming the first joint out of its limits.
        """
        table = self.table
        robot = self.robot
        out = []
        for i, value in zip(indices, values):
            lower = table.lower[i]
            upper = table.upper[i]
            if lower <= value <= upper:
                out.append(value * table.scale[i])
            elif within_limit(value, lower, upper):  # a rounding error past it: at the limit
                out.append(robot.lower[i] if value < lower else robot.upper[i])
            else:
                raise JointLimitError(robot.joint_names[i], i, value, lower, upper, table.unit[i])
        return out

    def from_si(self, values: Sequence[float]) -> list[float]:
        """Chain values in this source's units."""
        return [v / s for v, s in zip(values, self.table.scale)]


def _settle(future: asyncio.Future[str], reply: str) -> None:
    if not future.done():
        future.set_result(reply)
