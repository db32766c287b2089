"""One source's session: its robot, unit mode and marker style — the one way in.

Every change of the world comes through a ``Session``: a TCP connection has
one, so do a CRCL connection, a rosbridge client, the page and a replay. Doors
call ``run(line)`` (parse a text line and run it through its handler,
``registry.HANDLERS``), ``set_joints_batch`` (a run of ``joints`` lines at once)
or the typed calls (``calls``: ``set_joints``, ``plan_to``, ``play``,
``stop``, ``dwell``, ``grip``...); each tells the world what it was asked, in
one place (``notes``). This is the unit boundary: sources speak
degrees or radians (metres for prismatic joints, always); everything past the
session is SI. A handler checks a command whole before the world changes, so a
bad command never moves the robot partly.
"""

from __future__ import annotations

import asyncio
import functools
import itertools
import math
from collections.abc import Awaitable, Sequence
from typing import TypeVar

import numpy as np

from ..errors import C2rvizError
from ..ik.chain import Target
from ..motion.trajectory import PlannedTrajectory
from ..planning import EdgeResolution, edge_resolution
from ..protocol import replies
from ..protocol.grammar import numbers_batch, parse_line
from ..protocol.registry import HANDLERS, VERBS, Reply
from ..world.moves import Travel
from ..world.state import RobotState
from . import calls
from .guarded import guarded_go, unstopped
from .notes import Said, recorded, refused, taken, taken_all
from .services import Modes, Services
from .units import UnitEdge, UnitTable

T = TypeVar("T")
_CADENCE_S = 0.02  # a pause this soon after the previous one's end continues its cadence
BATCHED = tuple(f"{name} " for name in (VERBS["joints"].name, *VERBS["joints"].aliases))
"""How the lines ``Session.set_joints_batch`` may answer as one begin (a controller
streaming setpoints writes plain ``joints`` lines)."""


class Session(UnitEdge, Modes):
    """Applies one source's commands to the shared world.

    Attributes:
        source: Who speaks (``tcp 127.0.0.1:5123``, ``page``), for notes and errors.
        motion: ``off``, ``on`` or ``follow`` (``protocol.verbs.arm.MOTION_MODES``).
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
        listens: The last line run was ``watch``: the source only listens now (a virtual
            clock need not wait for it until it speaks).

    The doors' way in: ``run`` (a text line), ``set_joints_batch`` (a run of ``joints``
    lines), and the typed calls of ``calls`` (``set_joints``, ``plan_to``, ``play``,
    ``stop``, ``dwell``, ``grip``...), each telling the world of what it was asked
    (``notes.Said``). The handlers use ``go`` and ``execute``.
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
        self.listens = False
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

    # The one way in: text lines.

    def run(self, line: str) -> Reply | None:
        """Parse and run one line (None for a blank or comment line), telling the world of it
        (``notes.Said``): taken or refused, and its reply once known (a reply that waits is
        handed back as a future that tells it when it comes). A latency fault delays the
        reply, an error too (``notes.late``: handed back as an awaitable that raises it).

        Raises:
            C2rvizError: the line is refused (nothing changed); the world was told.
        """
        try:
            command = parse_line(line)
            if command is None:
                return None
            self.listens = False
            reply = HANDLERS[command.__class__](self, command)
        except C2rvizError as exc:
            self.listens = False
            return refused(self, line, exc)
        return taken(self, line, reply)

    def set_joints_batch(self, lines: Sequence[object], start: int) -> int:
        """Answer the run of plain ``joints`` lines of ``lines`` from ``start`` (each begins
        with one of ``BATCHED``) as one: with ``motion off`` and no guard, if there are two
        or more and every one has n values within the limits, only the last is applied (the
        ones before would be shown for no time at all), each is told to the world and
        answered ``ok``, and their count is returned; else 0, and nothing changed: run the
        lines one by one (``run``), so every reply and error is exactly as if they had been.
        """
        if self.motion != "off" or self.guard or self.world.faults.any(self.state.name):
            return 0
        texts: list[str] = []
        for line in itertools.islice(lines, start, None):
            if not isinstance(line, str) or not line.startswith(BATCHED):
                break
            texts.append(line)
        if len(texts) < 2:
            return 0
        flat = numbers_batch([t.partition(" ")[2] for t in texts], self.n)
        table = self.table
        if flat is None or not table.within(flat):
            return 0
        self.world.set_q(table.to_si(flat[-self.n :]), self.state.name, self.source)
        self.listens = False
        taken_all(self, texts, replies.OK)
        return len(texts)

    def execute(self, command: object) -> Reply:
        """Run a parsed ``command`` as ``run`` would, without telling the world of it; return
        its reply (or an awaitable of it), or raise a ``C2rvizError`` having changed nothing."""
        return HANDLERS[command.__class__](self, command)

    # The one way in: typed calls. ``said``: the command as its door shows it, told to the
    # world as ``run`` tells a line (None: the door tells it once, with ``said()``).

    def said(self, text: str) -> Said:
        """A command of this session as its door shows it, to tell the world of once."""
        return Said(self, text)

    def set_joints(
        self, q: Sequence[float], *, speed: float | None = None, said: str | Said | None = None
    ) -> Reply:
        """The chain to ``q`` [rad or m, within the limits] as ``go``, at ``speed`` % of the
        joints' limits (None: the session's)."""
        return recorded(self, said, functools.partial(self.go, q, speed))

    async def plan_to(
        self,
        target: Target,
        *,
        straight: bool = False,
        start: Sequence[float] | None = None,
    ) -> calls.Plan:
        """Solve (``straight``: plan and check the tool's straight line to) ``target`` (base
        frame, SI), from ``start`` [rad or m] (None: the arm now), off the loop; nothing moves.

        Raises:
            C2rvizError: out of reach, or (guarded line) it collides; ``ArmMoved``.
        """
        return await calls.plan_to(self, target, straight=straight, start=start)

    async def plan_through(
        self, targets: Sequence[Target], *, straight: bool = False
    ) -> list[calls.Plan]:
        """``plan_to`` each of ``targets`` in turn from the end of the one before; with the
        guard, each joint-space leg after the first is checked too (off the loop).

        Raises:
            WaypointError: naming the waypoint (1-based) that fails, and why.
        """
        return await calls.plan_through(self, targets, straight=straight)

    def play(
        self, plan: calls.Plan, *, speed: float | None = None, said: str | Said | None = None
    ) -> Reply:
        """Move as ``plan`` says, at ``speed`` % (None: the session's), as ``motion`` says.

        Raises:
            ArmMoved: a straight line's arm moved since it was planned.
        """
        return recorded(self, said, functools.partial(calls.play, self, plan, speed))

    def play_trajectory(
        self,
        trajectory: PlannedTrajectory,
        *,
        checked: bool = False,
        said: str | Said | None = None,
    ) -> Reply:
        """Play a checked timed trajectory from now (the arm at rest at its start), checked
        for collisions first with the guard (``calls.MAX_TRAJECTORY_CHECKS`` instants) unless
        ``checked`` (``check_trajectory`` checked it, off the loop, just before)."""
        play = functools.partial(calls.play_trajectory, self, trajectory, checked)
        return recorded(self, said, play)

    async def unstopped(self, work: Awaitable[T]) -> T:
        """A door's ``work`` off the loop for a move of this robot (its plan, its check):
        refused at once while a stop holds the robot, and when it ends if a stop came
        meanwhile (``guarded.unstopped``: a move asked before a stop never plays after it).

        Raises:
            FaultStop, MotionInterrupted: the stop.
        """
        return await unstopped(self, work)

    async def check_trajectory(self, trajectory: PlannedTrajectory) -> None:
        """With the guard, check ``trajectory`` for collisions as ``play_trajectory`` would,
        off the loop on the session's worker; nothing moves.

        Raises:
            PathCollides: an instant of it collides.
        """
        await calls.check_trajectory(self, trajectory)

    def stop(self, *, fingers: bool = False, said: str | Said | None = None) -> Reply:
        """Brake the arm to rest within its limits (``fingers``: stop the gripper too)."""
        return recorded(self, said, functools.partial(calls.brake, self, fingers))

    def dwell(self, seconds: float, *, said: str | Said | None = None) -> Reply:
        """``ok`` in ``seconds`` [s] of the world's clock (``after``)."""
        return recorded(self, said, lambda: self.after(seconds, replies.OK))

    def grip(self, opening: float, *, said: str | Said | None = None) -> Reply:
        """The gripper's fingers to ``opening`` (0 closed .. 1 open), as ``motion`` says.

        Raises:
            NoGripper: the robot has none.
        """
        return recorded(self, said, functools.partial(calls.grip, self, opening))

    def go(self, q: Sequence[float], speed: float | None = None) -> Reply:
        """Send this session's robot to ``q`` [rad or m, checked] at ``speed`` % (None: the
        session's): at once (``motion off``), or travelling (``on``: the reply comes on
        arrival; ``follow``: ``ok`` now). The handlers' move; doors call ``set_joints``.

        With the guard, the move is checked (or planned around, ``guard plan``) off the
        event loop and played on the checked path (``guarded.guarded_go``): the reply
        is then always awaitable."""
        percent = self.speed if speed is None else speed
        if self.guard:
            return guarded_go(self, [q], percent)
        if self.motion == "off":
            self.world.set_q(q, self.state.name, self.source)
            return replies.OK
        arrival = self.world.travels.go(
            self.state, q, percent / 100.0, self.source, wait=self.motion == "on"
        )
        return replies.OK if arrival is None else arrival

    def now(self) -> tuple[float, ...]:
        """The robot's joints at this instant [rad or m] (mid-move too)."""
        return self.world.travels.now(self.state) if self.travel.active else self.state.q

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


def _settle(future: asyncio.Future[str], reply: str) -> None:
    if not future.done():
        future.set_result(reply)
