"""The fault model: each robot's active, latched and scheduled faults, and their rules.

Pure: no clock, no asyncio, no observers. Times are passed in (the world's clock, [s]);
random draws come from a generator passed in. ``world/fault_rules.FaultRules`` runs it
on the world (timers, braking, telling the observers).

The rules, one per kind (docs/faults.md):

- ``estop``: a latch; every move is refused (``EmergencyStop``) until the fault is cleared
  *and* ``reset`` comes.
- ``protective``: a latch; every move is refused (``ProtectiveStop``) until ``reset``.
- ``stall JOINT``: the joint holds the value it had when the fault began (``follow``); a
  move whose target needs it elsewhere ends with ``JointStalled``.
- ``noise SIGMA``: reported values get Gaussian noise of SIGMA (``sensed``).
- ``latency MS,JITTER``: replies come ``MS + U(0, JITTER)`` late (``delay_s``).
- ``disconnect``: happens once (nothing to keep).
- ``drop [PART]``: happens once: the gripper lets go of what it holds (``fault_rules``
  releases it by the parts' release rule).
- ``slip P``: a grasp the rule would make fails with chance P (``slips``).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import BadArguments, C2rvizError, EmergencyStop, JointStalled, ProtectiveStop, shown
from ..protocol import replies
from ..protocol.registry import usage
from ..protocol.verbs.faults import FaultSpec

MAX_SCHEDULED = 100
"""Faults scheduled at once per robot (``fault at``/``after``); past it one is refused."""
INSTANT = frozenset({"disconnect", "drop"})
"""Kinds that happen once when they begin: nothing is kept (``FaultKind.lasting``)."""
STALL_TOLERANCE = 1e-6
"""A target this close to a stalled joint's value [rad or m] does not need it to move."""


class TooManyScheduled(C2rvizError):
    """``fault at``/``after`` past ``MAX_SCHEDULED`` waiting faults."""

    def __init__(self, limit: int) -> None:
        self.limit = limit
        super().__init__(
            f"fault: {limit} faults are scheduled already (the limit); `fault clear` some first"
        )


@dataclass(frozen=True, slots=True)
class Fault:
    """One fault of a robot, in SI.

    Attributes:
        kind: A name of ``protocol.verbs.faults.FAULT_KINDS``.
        joint: ``stall``: the joint's index in the chain.
        sigma: ``noise``: the standard deviation [rad, or m for a prismatic joint].
        delay_s: ``latency``: the base delay [s].
        jitter_s: ``latency``: the most added at random [s].
        word: A kind's word argument as given (``drop``'s part; a camera's name).
        values: A kind's numbers, SI (``slip``'s chance).
    """

    kind: str
    joint: int | None = None
    sigma: float = 0.0
    delay_s: float = 0.0
    jitter_s: float = 0.0
    word: str = ""
    values: tuple[float, ...] = ()

    @property
    def key(self) -> str:
        """What it is kept under: its kind (``stall``: one per joint; a kind with a word,
        one per word)."""
        if self.joint is not None:
            return f"{self.kind} {self.joint}"
        return f"{self.kind} {self.word}" if self.word else self.kind

    def text(self, joint_names: tuple[str, ...]) -> str:
        """As an event or a listing says it, in SI (``stall joint_l``, ``noise 0.01``,
        ``latency 50,10`` [ms])."""
        if self.kind == "stall" and self.joint is not None:
            return f"stall {joint_names[self.joint]}"
        if self.kind == "noise":
            return f"noise {replies.numbers([self.sigma])}"
        if self.kind == "latency":
            ms = replies.numbers([self.delay_s * 1000.0, self.jitter_s * 1000.0])
            return f"latency {ms}"
        words = [self.kind, self.word] if self.word else [self.kind]
        if self.values:
            words.append(replies.numbers(self.values))
        return " ".join(words)


@dataclass(frozen=True, slots=True)
class Scheduled:
    """A fault that begins at clock time ``due`` [s]; ``number`` orders equal times."""

    due: float
    number: int
    fault: Fault


@dataclass(slots=True)
class Latch:
    """A stop that holds the robot: ``estop`` or ``protective``, since clock time ``since``;
    ``released``: the estop was cleared (only ``reset`` is missing)."""

    kind: str
    since: float
    released: bool = False


@dataclass(eq=False)
class RobotFaults:
    """One robot's faults.

    Attributes:
        joint_names: The robot's chain, for texts and errors.
        prismatic: Per joint, True for a prismatic one (errors say m, not rad).
        active: The lasting faults now, by ``Fault.key``, each with its start [s].
        latch: The stop that holds the robot, if any.
        held: Stalled joints: index -> the value it holds [rad or m].
        scheduled: Faults waiting for their time, soonest first.
        stops: The stops that have held the robot, counted: a move checked off the loop
            while one came (and maybe went) is refused (``FaultRules.refuse``).
        last_stop: The latest of them (it may be lifted now).
    """

    joint_names: tuple[str, ...]
    prismatic: tuple[bool, ...]
    active: dict[str, tuple[Fault, float]] = field(default_factory=dict)
    latch: Latch | None = None
    held: dict[int, float] = field(default_factory=dict)
    scheduled: list[Scheduled] = field(default_factory=list)
    stops: int = 0
    last_stop: Latch | None = None

    @property
    def any(self) -> bool:
        """Something here changes what a command does (a fast path must not skip it)."""
        return bool(self.active or self.latch)

    # Changes (each returns the event texts it makes, in order).

    def start(self, fault: Fault, t: float, q: tuple[float, ...]) -> list[str]:
        """``fault`` begins at clock time ``t`` [s], the arm at ``q`` [rad or m]."""
        events = [f"fault {fault.text(self.joint_names)}"]
        if fault.kind in INSTANT:
            return events
        if fault.key not in self.active:
            self.active[fault.key] = (fault, t)
        else:  # a new setting of the same kind replaces the old one, its start kept
            self.active[fault.key] = (fault, self.active[fault.key][1])
        if fault.kind == "estop":
            if self.latch is None or self.latch.kind != "estop":
                self._latch(Latch("estop", t))
            else:
                self.latch.released = False  # engaged again before its reset
        elif fault.kind == "protective" and self.latch is None:
            self._latch(Latch("protective", t))
        elif fault.kind == "stall" and fault.joint is not None:
            self.held.setdefault(fault.joint, q[fault.joint])
        return events

    def _latch(self, latch: Latch) -> None:
        self.latch = self.last_stop = latch
        self.stops += 1

    def clear(self, what: str) -> list[str]:
        """End the active faults of kind ``what`` (``all``: every one, and every scheduled
        one), and the scheduled ones of that kind; return the events."""
        events = []
        for key, (fault, _) in list(self.active.items()):
            if what not in ("all", fault.kind):
                continue
            del self.active[key]
            events.append(f"cleared {fault.text(self.joint_names)}")
            if fault.kind == "stall" and fault.joint is not None:
                self.held.pop(fault.joint, None)
            elif fault.kind == "estop" and self.latch is not None:
                self.latch.released = True
            elif fault.kind == "protective" and self.latch and self.latch.kind == "protective":
                self.latch = None
        self.scheduled = [s for s in self.scheduled if what not in ("all", s.fault.kind)]
        return events

    def reset(self, origin: float) -> list[str]:
        """Lift the stop (a pendant's reset). Nothing to lift: nothing happens.

        Raises:
            EmergencyStop: the estop is still engaged (``fault clear estop`` first).
        """
        latch = self.latch
        if latch is None:
            return []
        if latch.kind == "estop" and not latch.released:
            raise EmergencyStop(latch.since - origin, released=False)
        self.latch = None
        events = []
        if "protective" in self.active:
            del self.active["protective"]
            events.append("cleared protective")
        return [*events, "reset"]

    def add_scheduled(self, entry: Scheduled) -> None:
        """Keep ``entry`` until its time (``due_now`` hands it back).

        Raises:
            TooManyScheduled: ``MAX_SCHEDULED`` wait already.
        """
        if len(self.scheduled) >= MAX_SCHEDULED:
            raise TooManyScheduled(MAX_SCHEDULED)
        self.scheduled.append(entry)
        self.scheduled.sort(key=lambda s: (s.due, s.number))

    def due_now(self, t: float) -> list[Scheduled]:
        """Take the scheduled faults due at ``t`` [s], in order."""
        due = [s for s in self.scheduled if s.due <= t]
        self.scheduled = self.scheduled[len(due) :]
        return due

    # The rules.

    def refusal(self, origin: float) -> C2rvizError | None:
        """Why a move is refused now (None: it is not); times from ``origin`` [s]."""
        latch = self.latch
        if latch is None:
            return None
        if latch.kind == "estop":
            return EmergencyStop(latch.since - origin, latch.released)
        return ProtectiveStop(latch.since - origin)

    def follow(self, q: tuple[float, ...]) -> tuple[float, ...]:
        """Where the joints are when commanded to ``q``: stalled ones hold."""
        if not self.held:
            return q
        out = list(q)
        for joint, value in self.held.items():
            out[joint] = value
        return tuple(out)

    def stalled(self, target: tuple[float, ...]) -> JointStalled | None:
        """The error of a move to ``target`` that a stalled joint kept short (None: none)."""
        for joint, value in sorted(self.held.items()):
            if abs(target[joint] - value) > STALL_TOLERANCE:
                unit = "m" if self.prismatic[joint] else "rad"
                return JointStalled(self.joint_names[joint], value, unit)
        return None

    def sensed(self, q: tuple[float, ...], rng: np.random.Generator) -> tuple[float, ...]:
        """``q`` as the encoders report it: with noise, if a noise fault is on."""
        entry = self.active.get("noise")
        if entry is None:
            return q
        noise = rng.normal(0.0, entry[0].sigma, len(q))
        return tuple(float(v) for v in np.asarray(q, dtype=float) + noise)

    def slips(self, rng: np.random.Generator) -> bool:
        """A grasp the rule would make fails now (a ``slip P`` fault: one draw, true with
        chance P; no draw without the fault)."""
        entry = self.active.get("slip")
        if entry is None:
            return False
        return float(rng.random()) < entry[0].values[0]

    def delay_s(self, rng: np.random.Generator) -> float:
        """How late the next reply comes [s] (0: latency is off)."""
        entry = self.active.get("latency")
        if entry is None:
            return 0.0
        fault = entry[0]
        jitter = float(rng.uniform(0.0, fault.jitter_s)) if fault.jitter_s > 0 else 0.0
        return fault.delay_s + jitter

    def listing(self, origin: float) -> list[tuple[Fault, str]]:
        """Each active fault and ``since T``, the latch of a released estop, and each
        scheduled fault and ``at T`` (times from ``origin`` [s])."""
        out = [(fault, f"since {t - origin:.3f}") for fault, t in self.active.values()]
        latch = self.latch
        if latch is not None and latch.kind == "estop" and latch.released:
            out.append((Fault("estop"), f"released, reset needed since {latch.since - origin:.3f}"))
        out.extend((s.fault, f"at {s.due - origin:.3f}") for s in self.scheduled)
        return out


def replay_line(text: str) -> str | None:
    """The command that replays a fault event (``fault estop`` -> itself, ``cleared stall
    joint_l`` -> ``fault clear stall``, ``reset``), for a recording's command file; None for
    what would act on the replaying client itself (``latency``, ``disconnect``)."""
    words = text.split()
    if not words or (len(words) > 1 and words[1] in ("latency", "disconnect")):
        return None
    if words[0] == "cleared" and len(words) > 1:
        return f"fault clear {words[1]}"
    return text if words[0] in ("fault", "reset") else None


def at_once(line: str) -> bool:
    """A recording writes this fault line (``replay_line``'s) at its time even while the arm
    moves: it refuses no frame of the replay (``fault drop``: the replay drops the part
    where the run did). Other lines wait for the arm to rest."""
    words = line.split()
    return len(words) > 1 and words[0] == "fault" and words[1] == "drop"


def to_fault(
    robot: str, joint_names: tuple[str, ...], angle_scale: float, spec: FaultSpec
) -> Fault:
    """``spec`` (a client's units: SI angle = its angle * ``angle_scale``) as the world's
    fault (SI) on ``robot`` (whose chain is ``joint_names``).

    Raises:
        BadArguments: a joint the robot does not have (naming those it has).
    """
    if spec.kind == "stall":
        return Fault("stall", joint=_joint(robot, joint_names, spec.word))
    if spec.kind == "noise":
        return Fault("noise", sigma=spec.values[0] * angle_scale)
    if spec.kind == "latency":
        delay_ms, jitter_ms = spec.values
        return Fault("latency", delay_s=delay_ms / 1000.0, jitter_s=jitter_ms / 1000.0)
    return Fault(spec.kind, word=spec.word, values=spec.values)  # a kind with no rule here


def _joint(robot: str, names: tuple[str, ...], word: str) -> int:
    if word.isascii() and word.isdigit() and int(word) < len(names):
        return int(word)
    if word in names:
        return names.index(word)
    raise BadArguments(
        "fault",
        f"no joint {shown(word)}: {robot} has {', '.join(names)} (or 0..{len(names) - 1})",
        usage("fault"),
    )
