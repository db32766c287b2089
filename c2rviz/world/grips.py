"""Grippers that take time: each robot's fingers moving to an opening on the world's clock.

``Grips`` belongs to the ``World``, beside ``Travels``. A move of the fingers runs at
the gripper's full speed (closed to open in ``Gripper.stroke_s``) from the opening
shown now, along a smooth ramp (zero speed at both ends); a timer on the asyncio loop
samples every moving gripper once per frame, publishes the opening through the
world's fan-out and settles the replies that wait for it: ``ok`` on arrival, an
error when another command takes over or stops it. The session checked the command.
"""

from __future__ import annotations

import asyncio
import math
from collections.abc import Callable
from dataclasses import dataclass, field

from ..errors import MotionInterrupted
from ..protocol import replies
from .clock import Clock, Timer
from .state import MoveRules, RobotState


@dataclass(eq=False)
class Grip:
    """One gripper's move: from ``start`` at ``t0`` to ``goal`` at ``t1`` [clock s]."""

    state: RobotState
    start: float = 0.0
    goal: float = 0.0
    t0: float = 0.0
    t1: float = 0.0
    active: bool = False
    reply: str = replies.OK
    arrivals: list[asyncio.Future[str]] = field(default_factory=list)

    def at(self, t: float) -> float:
        """The opening at time ``t`` (smoothstep between start and goal)."""
        if t >= self.t1 or self.t1 <= self.t0:
            return self.goal
        s = max((t - self.t0) / (self.t1 - self.t0), 0.0)
        return self.start + (self.goal - self.start) * s * s * (3.0 - 2.0 * s)


class Grips:
    """The gripper moves of every robot of a world, and the frame timer that plays them."""

    def __init__(
        self,
        publish: Callable[[RobotState, float, float], None],
        clock: Clock,
        frame_s: float,
    ) -> None:
        """Set up.

        Args:
            publish: ``publish(state, opening, t)`` shows a gripper at ``opening`` at ``t``.
            clock: The world's clock.
            frame_s: Time between two samples of a moving gripper [s].
        """
        self.publish = publish
        self.clock = clock
        self.frame_s = frame_s
        self.by_robot: dict[str, Grip] = {}
        self._timer: Timer | None = None
        self.rules = MoveRules()
        """Faults' say in gripper moves (the world sets its ``FaultRules``: a stop refuses)."""

    def _grip(self, state: RobotState) -> Grip:
        grip = self.by_robot.get(state.name)
        if grip is None:
            grip = self.by_robot[state.name] = Grip(state)
        return grip

    def now(self, state: RobotState) -> float:
        """The opening at this instant (between two frames, too)."""
        grip = self.by_robot.get(state.name)
        return grip.at(self.clock.now()) if grip is not None and grip.active else state.opening

    def moving(self, state: RobotState) -> bool:
        grip = self.by_robot.get(state.name)
        return grip is not None and grip.active

    def set(self, state: RobotState, opening: float, source: str) -> None:
        """Put the fingers at ``opening`` now (a move under way ends here)."""
        self.rules.refuse(state)
        grip = self._grip(state)
        _interrupt(grip, f"preempted by {source}")
        grip.active = False
        state.opening_target = opening
        self.publish(state, opening, self.clock.now())

    def go(
        self,
        state: RobotState,
        opening: float,
        source: str,
        wait: bool,
        reply: str = replies.OK,
    ) -> asyncio.Future[str] | None:
        """Move the fingers to ``opening`` (0..1, checked) at the gripper's speed.

        Args:
            reply: What the wait ends with on arrival (closing on a part: its opening).

        Returns:
            With ``wait``, the reply that comes on arrival (``ok``) or an error when
            another move or a stop takes over; else None.
        """
        assert state.robot.gripper is not None
        self.rules.refuse(state)
        grip = self._grip(state)
        _interrupt(grip, f"preempted by {source}")
        t = self.clock.now()
        grip.start = self.now(state)
        grip.goal = state.opening_target = opening
        grip.reply = reply
        grip.t0, grip.t1 = t, t + abs(opening - grip.start) * state.robot.gripper.stroke_s
        grip.active = grip.t1 > t
        arrival: asyncio.Future[str] | None = None
        if wait:  # the clock's future: a virtual clock lets time run while it waits
            arrival = self.clock.future()
            grip.arrivals.append(arrival)
        if grip.active:
            if self._timer is None:
                self._timer = self.clock.call_later(0.0, self._tick)
        else:
            self.publish(state, opening, t)
            _settle(grip)
        return arrival

    def stop(self, state: RobotState, source: str) -> None:
        """The fingers stop where they are (they are light: at once)."""
        grip = self.by_robot.get(state.name)
        if grip is None or not grip.active:
            return
        opening = grip.at(self.clock.now())
        _interrupt(grip, f"motion stopped by {source}")
        grip.active = False
        state.opening_target = opening
        self.publish(state, opening, self.clock.now())

    def stop_all(self) -> None:
        """The program stops: no more frames."""
        if self._timer is not None:
            self._timer.cancel()
            self._timer = None

    def _tick(self) -> None:
        self._timer = None
        t = self.clock.now()
        due = math.inf
        for grip in self.by_robot.values():
            if not grip.active:
                continue
            self.publish(grip.state, grip.at(t), t)
            if t >= grip.t1:
                grip.active = False
                _settle(grip)
            else:
                due = min(due, t + self.frame_s, grip.t1)
        if due < math.inf:
            self._timer = self.clock.call_at(max(due, self.clock.now()), self._tick)


def _interrupt(grip: Grip, why: str) -> None:
    waiting, grip.arrivals = grip.arrivals, []
    for future in waiting:
        if not future.done():
            future.set_exception(MotionInterrupted(why))


def _settle(grip: Grip) -> None:
    waiting, grip.arrivals = grip.arrivals, []
    for future in waiting:
        if not future.done():
            future.set_result(grip.reply)
