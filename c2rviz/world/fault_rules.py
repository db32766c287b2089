"""Faults on the world: the model (``faults.RobotFaults``) run on the world's clock.

``FaultRules`` belongs to the ``World`` (``world.faults``), so every door meets a fault
alike: a move from any door reaches ``World.set_q`` or ``Travels.go``/``play``, which ask
``refuse``; a moving arm's samples pass through ``follow`` and its arrival through
``arrival_error``. What a door reports of the joints passes through ``sensed``; a
session's replies pass through ``delayed`` (ok and error alike: ``session/notes``) and a
CRCL connection's statuses through ``late_sends`` (``clock.py``'s latency makes them wait on the
clock). A fault that begins, ends or is lifted is told to every observer
(``Observer.on_fault``: ``watch`` streams, rosbridge's ``/diagnostics``, the page) and
listener (the text and CRCL doors and rosbridge's bridge, for ``disconnect``). A ``drop``
releases what the robot holds through the world's parts (``WorldParts.release``), and
the parts ask ``slips`` before each grasp the rule would make.

Scheduled faults are timers on the world's clock, so virtual time runs them exactly.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Awaitable, Callable, Mapping
from typing import TYPE_CHECKING, TypeVar

import numpy as np

from ..errors import BadArguments, C2rvizError, MotionInterrupted, shown
from ..protocol.registry import usage
from .clock import Clock, LateSends, Timer, late
from .faults import Fault, RobotFaults, Scheduled
from .moves import Travels
from .state import MoveRules, RobotState

if TYPE_CHECKING:
    from .cameras import Cameras
    from .part_world import WorldParts


T = TypeVar("T")


class FaultRules(MoveRules):
    """Every robot's faults, applied to one world. Used from the asyncio thread only.

    Attributes:
        origin: Clock time [s] that fault times count from (the server's start: the
            ``watch`` stream's origin, once the services bind it).
        rng: The noise and jitter draws (the services give a child of ``--seed``'s).
        late: Some robot has a latency fault (``session/notes`` looks before anything else).
    """

    def __init__(
        self,
        robots: Mapping[str, RobotState],
        clock: Clock,
        travels: Travels,
        tell: Callable[[str, str], None],
    ) -> None:
        """Set up for the world's ``robots``, ``clock`` and ``travels``; ``tell(robot, text)``
        hands a change to every observer (``Observer.on_fault``)."""
        self.states = robots
        self.clock = clock
        self.travels = travels
        self.tell = tell
        self.origin = clock.now()
        self.rng = np.random.default_rng()
        self.late = False
        self.robots = {
            name: RobotFaults(state.robot.joint_names, state.robot.prismatic)
            for name, state in robots.items()
        }
        self._numbers = itertools.count()
        self._timers: dict[str, Timer] = {}
        self.listeners: list[Callable[[str, str], None]] = []
        """Called as observers are (``listener(robot, text)``), by what is no observer: the
        TCP door, which closes a robot's clients on ``fault disconnect``."""
        self.parts: WorldParts | None = None
        """The world's parts, which ``fault drop`` releases (the world sets it)."""
        self.cameras: Cameras | None = None
        """The world's cameras, which ``fault blackout`` darkens (the world sets it)."""

    def bind(self, rng: np.random.Generator, origin: float) -> None:
        """Draw from ``rng`` and count times from ``origin`` [s] from now on."""
        self.rng = rng
        self.origin = origin

    def of(self, robot: str) -> RobotFaults:
        return self.robots[robot]

    def any(self, robot: str) -> bool:
        """A fault changes what ``robot``'s commands do (fast paths must not skip it)."""
        return self.robots[robot].any

    # What moves ask (Travels and World.set_q).

    def refuse(self, state: RobotState, stops: int | None = None) -> None:
        """Raise why a move of ``state`` is refused now (a stop), if it is; and, given
        ``stops`` (``of(robot).stops`` when the move was asked), why a move asked before a
        stop that came since (and may be lifted now) is refused: it was asked of an arm
        that stopped, and never plays after the stop's ``reset``."""
        faults = self.robots[state.name]
        if faults.latch is not None:
            error = faults.refusal(self.origin)
            if error is not None:
                raise error
        stop = faults.last_stop
        if stops is not None and faults.stops != stops and stop is not None:
            raise MotionInterrupted(
                f"a stop ({stop.kind} at t={stop.since - self.origin:.3f}) came while this "
                "move was checked; nothing moved, send it again"
            )

    def follow(self, state: RobotState, q: tuple[float, ...]) -> tuple[float, ...]:
        """Where ``state``'s joints are when commanded to ``q``."""
        return self.robots[state.name].follow(q)

    def arrival_error(self, state: RobotState) -> C2rvizError | None:
        """The error a move of ``state`` that came to rest at its target ends with."""
        faults = self.robots[state.name]
        return faults.stalled(state.target) if faults.held else None

    # What doors ask.

    def sensed(self, robot: str, q: tuple[float, ...]) -> tuple[float, ...]:
        """``robot``'s joints ``q`` as its encoders report them (noise, if on)."""
        faults = self.robots[robot]
        return faults.sensed(q, self.rng) if faults.active else q

    def slips(self, robot: str) -> bool:
        """A grasp by ``robot`` that the rule would make fails now (``slip P``: a draw)."""
        faults = self.robots[robot]
        return faults.slips(self.rng) if faults.active else False

    def reply_delay(self, robot: str) -> float:
        """How late the reply made now to a client of ``robot`` comes [s] (0: no latency
        fault; a jitter is drawn per reply)."""
        return self.robots[robot].delay_s(self.rng)

    def delayed(
        self, robot: str, reply: str | Awaitable[str] | C2rvizError
    ) -> str | Awaitable[str] | C2rvizError:
        """``reply`` to a client of ``robot`` (its text, an awaitable of it, or the error it
        is refused with) as it is, or, with a latency fault on, an awaitable that gives the
        text or raises the error that much later on the world's clock (a reply that waits:
        that much after it comes, ``ok`` or error alike)."""
        delay = self.reply_delay(robot)
        return reply if delay <= 0.0 else late(reply, delay, self.clock)

    def late_sends(self, robot: Callable[[], str], send: Callable[[T], None]) -> LateSends[T]:
        """``send`` for a door that sends unasked (CRCL statuses), each message late by the
        latency fault of ``robot()`` (its client's robot when it is made), in order."""
        return LateSends(send, lambda: self.reply_delay(robot()), self.clock)

    # What the verbs do.

    def start(self, robot: str, fault: Fault, *, strict: bool = True) -> None:
        """``fault`` begins on ``robot`` now.

        Raises:
            BadArguments: with ``strict`` (a client's ``fault``, not a scheduled one coming
                due), ``drop PART`` of a part the robot does not hold; nothing changes.
        """
        if fault.kind == "drop" and fault.word and strict:
            self._held(robot, fault.word)
        if fault.kind == "blackout":
            self._blackout(robot, fault, strict)
            return
        state = self.states[robot]
        travels = self.travels
        faults = self.robots[robot]
        events = faults.start(fault, self.clock.now(), travels.now(state))
        if fault.kind == "estop":
            travels.halt(state, str(faults.refusal(self.origin)))
        elif fault.kind == "protective":
            travels.stop(state, "", str(faults.refusal(self.origin)))
        elif fault.kind == "stall":
            travels.resync(state)
        elif fault.kind == "disconnect":  # after this reply is written
            self.clock.call_later(0.0, self._tell, robot, events)
            return
        elif fault.kind == "drop":  # the event first, then what it released
            self._tell(robot, events)
            if self.parts is not None:
                self.parts.release(robot, fault.word or None)
            return
        self.late = any("latency" in f.active for f in self.robots.values())
        self._tell(robot, events)

    def schedule(self, robot: str, fault: Fault, due: float) -> None:
        """``fault`` begins on ``robot`` at clock time ``due`` [s].

        Raises:
            TooManyScheduled: too many wait already (nothing changes).
        """
        self.robots[robot].add_scheduled(Scheduled(due, next(self._numbers), fault))
        self._arm(robot)

    def clear(self, robot: str, what: str) -> None:
        """End ``robot``'s faults of kind ``what`` (``all``: all, scheduled ones too)."""
        faults = self.robots[robot]
        stalled = bool(faults.held)
        events = faults.clear(what)
        if what in ("blackout", "all") and self.cameras is not None:
            for camera in self.cameras.all():
                if camera.blackout_until > self.clock.now():
                    self.cameras.blackout(camera.name, -math.inf)
                    events.append(f"cleared blackout {camera.name}")
        if stalled and not faults.held:
            self.travels.resync(self.states[robot])
        self.late = any("latency" in f.active for f in self.robots.values())
        self._arm(robot)
        self._tell(robot, events)

    def reset(self, robot: str) -> None:
        """Lift ``robot``'s stop.

        Raises:
            EmergencyStop: the estop is still engaged.
        """
        self._tell(robot, self.robots[robot].reset(self.origin))

    def close(self) -> None:
        """The program stops: no scheduled fault fires."""
        for timer in self._timers.values():
            timer.cancel()
        self._timers.clear()

    # Inside.

    def _arm(self, robot: str) -> None:
        """A timer for ``robot``'s soonest scheduled fault (none: no timer)."""
        timer = self._timers.pop(robot, None)
        if timer is not None:
            timer.cancel()
        scheduled = self.robots[robot].scheduled
        if scheduled:
            self._timers[robot] = self.clock.call_at(scheduled[0].due, self._fire, robot)

    def _fire(self, robot: str) -> None:
        self._timers.pop(robot, None)
        for entry in self.robots[robot].due_now(self.clock.now()):
            self.start(robot, entry.fault, strict=False)
        self._arm(robot)

    def _blackout(self, robot: str, fault: Fault, strict: bool) -> None:
        """Darken camera ``fault.word`` for ``fault.values[0]`` s (none: until cleared).

        Raises:
            UnknownCamera: with ``strict`` (a scheduled one coming due is no error).
        """
        cameras = self.cameras
        if cameras is None or (not strict and fault.word not in cameras):
            return
        cameras.get(fault.word)  # raises, naming the cameras there are
        now = self.clock.now()
        until = now + fault.values[0] if fault.values else math.inf
        cameras.blackout(fault.word, until)
        if math.isfinite(until):  # the page and feeds hear when it ends
            self.clock.call_at(until, self._light, fault.word, until)
        self._tell(
            robot,
            [f"fault blackout {fault.word}" + (f" {fault.values[0]:g}" if fault.values else "")],
        )

    def _light(self, name: str, until: float) -> None:
        """A blackout's time is over (unless a newer one or a clear changed it)."""
        cameras = self.cameras
        if cameras is not None and name in cameras and cameras.get(name).blackout_until == until:
            cameras.blackout(name, -math.inf)

    def _held(self, robot: str, name: str) -> None:
        """Raise unless ``robot`` holds the part ``name``."""
        held = [p.name for p in self.parts.parts.held_by(robot)] if self.parts else []
        if name not in held:
            holds = ", ".join(held) if held else "nothing"
            raise BadArguments(
                "fault", f"{robot} does not hold {shown(name)} (it holds {holds})", usage("fault")
            )

    def _tell(self, robot: str, events: list[str]) -> None:
        for text in events:
            self.tell(robot, text)
            for listener in list(self.listeners):
                listener(robot, text)
