"""Moves that take time: each robot's planned motion on the world's clock.

``Travels`` belongs to the ``World``. A move to a target plans a ruckig
trajectory (``motion.Motion``) from the arm's state now; a timer on the asyncio
loop samples every moving robot once per frame (``1/hz``), publishes the pose
through the world's fan-out, and settles the replies that wait for the arm:
``ok`` on arrival, or an error when another command preempts or stops the
move. Nothing here parses or checks a command: the session did.
"""

from __future__ import annotations

import asyncio
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

from ..errors import MotionInterrupted
from ..motion.limits import MotionLimits
from ..motion.path_play import PathPlay
from ..motion.planner import Motion
from ..protocol import replies
from .clock import Clock, Timer
from .state import MoveRules, RobotState

TICK_ROBOTS = 8  # robots sampled in one turn of the loop (64 robots: ~0.6 ms a turn)


@dataclass(eq=False)
class Travel:
    """One robot's motion and who waits on it.

    Attributes:
        state: The robot that moves.
        motion: The planner, sampled at the world's clock.
        active: A plan runs (the timer samples it each frame).
        synced: The planner stands where the robot is (instant commands, which may come
            by the hundred thousand, only clear this; the next move re-syncs).
        arrivals: Replies waiting for the arm to reach the running move's target.
        rests: Replies waiting for the arm to come to rest (``wait``, ``stop``).
        path: A path being played instead of ``motion`` (a straight tool line, a planned
            path, a timed trajectory), if any.
        stopping: The running move was stopped (``stop``): it ends at rest short of
            its target. Cleared by the next move.
    """

    state: RobotState
    motion: Motion
    active: bool = False
    synced: bool = True
    path: PathPlay | None = None
    stopping: bool = False
    arrivals: list[asyncio.Future[str]] = field(default_factory=list)
    rests: list[asyncio.Future[str]] = field(default_factory=list)


class Travels:
    """The motions of every robot of a world, and the frame timer that plays them."""

    def __init__(
        self,
        publish: Callable[[RobotState, tuple[float, ...], float], None],
        rested: Callable[[RobotState, bool], None],
        clock: Clock,
        frame_s: float,
        planned: Callable[[RobotState, float], None] | None = None,
    ) -> None:
        """Set up.

        Args:
            publish: ``publish(state, q, t)`` shows a robot at ``q`` at time ``t``.
            rested: ``rested(state, stopped)``: a move came to rest, at its target or
                (``stopped``) short of it after a stop; not called for a move an
                instant command cut short.
            clock: The world's clock.
            frame_s: Time between two samples of a moving arm [s].
            planned: ``planned(state, t)``: the robot's motion changed at ``t`` (a move
                started, a stop, a preemption).
        """
        self.publish = publish
        self.rested = rested
        self.clock = clock
        self.frame_s = frame_s
        self.planned = planned
        self.by_robot: dict[str, Travel] = {}
        self.rules = MoveRules()
        """Faults' say in moves (the world sets its ``FaultRules``)."""
        self._timer: Timer | None = None
        self._round: list[Travel] = []  # the frame's robots still to sample
        self._due = math.inf  # the next frame [s], as far as this frame's robots say

    def add(self, state: RobotState, limits: MotionLimits) -> Travel:
        travel = self.by_robot[state.name] = Travel(state, Motion(limits, state.q))
        return travel

    # What the world does with a robot's target.

    def preempt(self, travel: Travel, source: str) -> None:
        """An instant command puts the arm somewhere now: the running move ends here."""
        self._interrupt(travel, f"preempted by {source}")
        travel.active = False
        travel.synced = False
        travel.path = None
        _settle(travel.rests, replies.OK)
        self._planned(travel)

    def go(
        self, state: RobotState, q: Sequence[float], speed: float, source: str, wait: bool
    ) -> asyncio.Future[str] | None:
        """Travel to ``q`` at ``speed`` (0..1 of the limits) from the arm's state now.

        Returns:
            With ``wait``, a reply that comes on arrival (``ok``) or when the move is
            preempted or stopped (an error); else None (``motion follow``).
        """
        self.rules.refuse(state)
        travel = self.by_robot[state.name]
        self._interrupt(travel, f"preempted by {source}")
        t = self.clock.now()
        if travel.path is not None:  # leaving a path: from its state if it tells it, else at rest
            state_at = getattr(travel.path, "state", None)
            if travel.active and callable(state_at):
                travel.motion.take_over(state_at(t), t)
            else:
                travel.motion.jump(travel.path.sample(t), t)
            travel.path = None
        elif not travel.synced:
            travel.motion.jump(state.q, t)
        travel.synced = True
        if wait:
            travel.motion.move_to(q, t, speed)
        else:
            travel.motion.follow(q, t, speed)
        state.target = travel.motion.target
        self._run(travel)
        self._planned(travel)
        if not wait:
            return None
        arrival: asyncio.Future[str] = self.clock.future()  # settled, its client is busy
        travel.arrivals.append(arrival)
        if not travel.active:  # already there: nothing to wait for
            self._arrived(travel)
        return arrival

    def play(
        self, state: RobotState, path: PathPlay, source: str, wait: bool
    ) -> asyncio.Future[str] | None:
        """Play ``path`` (which starts where the arm is, at rest, on the world's clock).

        Returns:
            As ``go``: with ``wait`` a reply on arrival, else None.
        """
        self.rules.refuse(state)
        travel = self.by_robot[state.name]
        self._interrupt(travel, f"preempted by {source}")
        travel.path = path
        travel.synced = False
        state.target = path.sample(path.arrival)
        travel.active = True
        self._run(travel)
        self._planned(travel)
        if not wait:
            return None
        arrival: asyncio.Future[str] = self.clock.future()  # settled, its client is busy
        travel.arrivals.append(arrival)
        return arrival

    def stop(
        self, state: RobotState, source: str, why: str | None = None
    ) -> asyncio.Future[str] | None:
        """Decelerate to rest at the joints' full limits, on the path where there is one
        (a path played, a straight move from rest); return the reply that comes at rest
        (None: at rest now). The move's waiters hear ``why`` (default: stopped by
        ``source``)."""
        travel = self.by_robot[state.name]
        if not travel.active:
            return None
        self._interrupt(travel, why or f"motion stopped by {source}")
        travel.stopping = True
        if travel.path is not None:  # a path brakes on the path
            travel.path.brake(self.clock.now())
            state.target = travel.path.sample(travel.path.arrival)
        else:
            travel.motion.stop(self.clock.now())
            state.target = travel.motion.target
        self._planned(travel)
        return self.rest(state)

    def halt(self, state: RobotState, why: str) -> None:
        """Stop the arm where it is, in this instant (an emergency stop); the move's
        waiters hear ``why``."""
        travel = self.by_robot[state.name]
        if not travel.active:
            return
        q = self.now(state)
        self._interrupt(travel, why)
        travel.active = False
        travel.synced = False
        travel.path = None
        state.target = q
        self.publish(state, q, self.clock.now())
        self._planned(travel)
        self.rested(state, True)
        _settle(travel.rests, replies.OK)

    def resync(self, state: RobotState) -> None:
        """The arm's joints may stand apart from its planner's (a stall began or ended):
        the next move starts from where they stand."""
        travel = self.by_robot[state.name]
        if not travel.active:
            travel.synced = False

    def rest(self, state: RobotState) -> asyncio.Future[str] | None:
        """The reply that comes when the arm is at rest (None: it is now)."""
        travel = self.by_robot[state.name]
        if not travel.active:
            return None
        future: asyncio.Future[str] = self.clock.future()
        travel.rests.append(future)
        return future

    def seconds_left(self, state: RobotState) -> float:
        """Time until the arm is at rest [s]; 0 when it is."""
        travel = self.by_robot[state.name]
        if not travel.active:
            return 0.0
        end = travel.path.arrival if travel.path is not None else travel.motion.arrival()
        return max(end - self.clock.now(), 0.0)

    def now(self, state: RobotState) -> tuple[float, ...]:
        """Where the arm is at this instant (between two frames, too)."""
        travel = self.by_robot[state.name]
        if not travel.active:
            return state.q
        if travel.path is not None:
            return self.rules.follow(state, travel.path.sample(self.clock.now()))
        return self.rules.follow(state, travel.motion.sample(self.clock.now())[0])

    def stop_all(self) -> None:
        """The program stops: no more frames."""
        if self._timer is not None:
            self._timer.cancel()
            self._timer = None

    def _planned(self, travel: Travel) -> None:
        if self.planned is not None:
            self.planned(travel.state, self.clock.now())

    # The frame timer.

    def _run(self, travel: Travel) -> None:
        travel.active = travel.path is not None or travel.motion.moving(self.clock.now())
        if travel.active and self._timer is None:
            self._timer = self.clock.call_later(0.0, self._tick)

    def _tick(self) -> None:
        """Sample every moving robot, publish it, settle the arrived; come back next frame.

        A frame's robots are sampled ``TICK_ROBOTS`` at a time, the loop taking a turn
        between (a client's line is answered meanwhile), each at the clock's time of its
        turn."""
        self._timer = None
        self._round = [travel for travel in self.by_robot.values() if travel.active]
        self._due = math.inf
        self._turn()

    def _turn(self) -> None:
        self._timer = None
        t = self.clock.now()
        batch, self._round = self._round[:TICK_ROBOTS], self._round[TICK_ROBOTS:]
        for travel in batch:
            if not travel.active:  # stopped since the frame began
                continue
            path = travel.path
            if path is not None:
                q = path.sample(t)
                end = path.arrival
                if t >= end:  # at rest at the path's end: the planner stands there too
                    travel.active, travel.path = False, None
                    travel.motion.jump(q, t)
                    travel.synced = True
            else:
                q = travel.motion.sample(t)[0]
                end = travel.motion.arrival()
                if not travel.motion.moving(t):
                    travel.active = False
            self.publish(travel.state, self.rules.follow(travel.state, q), t)
            if travel.active:
                self._due = min(self._due, t + self.frame_s, end)
            else:
                self.rested(travel.state, travel.stopping)
                self._arrived(travel)
                _settle(travel.rests, replies.OK)
        if self._round:
            self._timer = self.clock.call_later(0.0, self._turn)
        elif any(travel.active for travel in self.by_robot.values()):
            # (one set going since the frame began waits for the next frame)
            due = self._due if self._due < math.inf else t + self.frame_s
            self._timer = self.clock.call_at(max(due, self.clock.now()), self._tick)

    def _arrived(self, travel: Travel) -> None:
        """The move came to rest at its target: ``ok``, unless a fault kept it short."""
        error = self.rules.arrival_error(travel.state)
        if error is None:
            _settle(travel.arrivals, replies.OK)
            return
        travel.synced = False  # the planner stands at the target, the arm does not
        waiting, travel.arrivals = travel.arrivals, []
        for future in waiting:
            if not future.done():
                future.set_exception(error)

    @staticmethod
    def _interrupt(travel: Travel, why: str) -> None:
        """The running move ends (a new one, or a stop, follows): its waiters hear ``why``."""
        travel.stopping = False
        waiting, travel.arrivals = travel.arrivals, []
        for future in waiting:
            if not future.done():
                future.set_exception(MotionInterrupted(why))


def _settle(futures: list[asyncio.Future[str]], reply: str) -> None:
    waiting = list(futures)
    futures.clear()
    for future in waiting:
        if not future.done():
            future.set_result(reply)
