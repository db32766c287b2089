"""Fault verbs: make things go wrong on purpose, now or on the world's clock.

``fault KIND ARGS`` starts a fault on the connection's robot, ``fault at T KIND ARGS``
and ``fault after S KIND ARGS`` schedule one, ``fault clear [KIND|all]`` ends them,
``faults`` lists them and ``reset`` lifts a stop (docs/faults.md).

Each kind of fault is one entry of ``FAULT_KINDS``: its name, its arguments, what it
does, and the parser of its arguments; a new kind (a gripper's drop, a camera's
blackout) is one more entry here and one rule in ``world/faults.py``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from ...errors import BadArguments, shown
from ..grammar import numbers
from ..registry import usage, verb

FAULT_TIME_S = 1e6
"""``fault at T`` and ``fault after S``: T and S lie within 0..this [s of the world's clock]."""
NOISE_SIGMA = 100.0
"""``fault noise SIGMA``: SIGMA lies above 0 and at most this, in the connection's unit."""
LATENCY_MS = 60_000.0
"""``fault latency MS[,JITTER]``: MS and JITTER lie within 0..this [ms]."""


@dataclass(frozen=True, slots=True)
class FaultSpec:
    """One fault as a client asked for it, in the client's units (the session converts).

    Attributes:
        kind: A name of ``FAULT_KINDS``.
        word: A word argument: ``stall``'s joint (its name or index); ``drop``'s part;
            ``blackout``'s camera.
        values: Numbers: ``noise``'s SIGMA; ``latency``'s MS and JITTER [ms]; ``slip``'s P;
            ``blackout``'s S [s].
    """

    kind: str
    word: str = ""
    values: tuple[float, ...] = ()


@dataclass(frozen=True, slots=True)
class FaultKind:
    """One kind of fault of the language.

    Attributes:
        name: What ``fault NAME`` calls it.
        args: Its argument pattern (``""``: none).
        summary: What it does, for docs and ``help``.
        parse: ``parse(words) -> FaultSpec``; raises ``BadArguments`` (as ``fault``).
        lasting: It stays until cleared (False: it happens once, as ``disconnect``).
    """

    name: str
    args: str
    summary: str
    parse: Callable[[list[str]], FaultSpec]
    lasting: bool = True

    @property
    def usage(self) -> str:
        return f"{self.name} {self.args}" if self.args else self.name


def _bad(problem: str) -> BadArguments:
    return BadArguments("fault", problem, usage("fault"))


def _none(name: str) -> Callable[[list[str]], FaultSpec]:
    def parse(words: list[str]) -> FaultSpec:
        if words:
            raise _bad(f"{name} takes no argument, got {shown(' '.join(words))}")
        return FaultSpec(name)

    return parse


def _stall(words: list[str]) -> FaultSpec:
    if len(words) != 1:
        raise _bad("stall needs one joint (its name or index)")
    return FaultSpec("stall", words[0])


def _noise(words: list[str]) -> FaultSpec:
    if len(words) != 1:
        raise _bad("noise needs one SIGMA")
    values = numbers("fault", words[0])
    if len(values) != 1:
        raise _bad("noise needs one SIGMA")
    (sigma,) = values
    if not 0.0 < sigma <= NOISE_SIGMA:
        raise _bad(f"noise SIGMA {sigma:g} is outside (0, {NOISE_SIGMA:g}]")
    return FaultSpec("noise", values=values)


def _latency(words: list[str]) -> FaultSpec:
    if len(words) != 1:
        raise _bad("latency needs MS[,JITTER]")
    values = numbers("fault", words[0])
    if len(values) > 2:
        raise _bad("latency needs MS[,JITTER]")
    for name, value in zip(("MS", "JITTER"), values):
        if not 0.0 <= value <= LATENCY_MS:
            raise _bad(f"latency {name} {value:g} is outside 0..{LATENCY_MS:g} ms")
    return FaultSpec("latency", values=(values[0], values[1] if len(values) == 2 else 0.0))


def _drop(words: list[str]) -> FaultSpec:
    if len(words) > 1:
        raise _bad("drop takes at most one PART")
    return FaultSpec("drop", words[0] if words else "")


def _slip(words: list[str]) -> FaultSpec:
    values = numbers("fault", words[0]) if len(words) == 1 else ()
    if len(values) != 1:
        raise _bad("slip needs one P (a chance per grasp, 0..1)")
    if not 0.0 <= values[0] <= 1.0:
        raise _bad(f"slip P {values[0]:g} is outside 0..1 (a chance per grasp)")
    return FaultSpec("slip", values=values)


def _blackout(words: list[str]) -> FaultSpec:
    if len(words) not in (1, 2):
        raise _bad("blackout needs a CAMERA and, if it ends by itself, S [s]")
    if len(words) == 1:
        return FaultSpec("blackout", words[0])
    values = numbers("fault", words[1])
    if len(values) != 1 or not 0.0 < values[0] <= FAULT_TIME_S:
        raise _bad(f"blackout S {shown(words[1])} is not a time in (0, {FAULT_TIME_S:g}] s")
    return FaultSpec("blackout", words[0], values)


FAULT_KINDS: dict[str, FaultKind] = {
    kind.name: kind
    for kind in (
        FaultKind(
            "estop",
            "",
            "emergency stop: the arm stops where it is; every move is refused until "
            "`fault clear estop`, then `reset`",
            _none("estop"),
        ),
        FaultKind(
            "protective",
            "",
            "protective stop: the arm brakes on its path; every move is refused until `reset`",
            _none("protective"),
        ),
        FaultKind(
            "stall",
            "JOINT",
            "the joint (name or index) stops following; a move that needs it to move ends "
            "with `error: JOINT stalled at V rad`",
            _stall,
        ),
        FaultKind(
            "noise",
            "SIGMA",
            "reported joint values carry Gaussian encoder noise of SIGMA (the connection's "
            "angle unit; metres for a prismatic joint's SI value); commanded ones do not",
            _noise,
        ),
        FaultKind(
            "latency",
            "MS[,JITTER]",
            "replies to this robot's clients come MS ms late (plus 0..JITTER ms), on the "
            "world's clock",
            _latency,
        ),
        FaultKind(
            "disconnect",
            "",
            "the server closes this robot's client connections now (they may reconnect)",
            _none("disconnect"),
            lasting=False,
        ),
        FaultKind(
            "drop",
            "[PART]",
            "the gripper lets go of what it holds now (only PART, which it must hold); it "
            "rests or falls as if the fingers opened",
            _drop,
            lasting=False,
        ),
        FaultKind(
            "slip",
            "P",
            "each grasp the rule would make fails with chance P (0..1, drawn from the seed): "
            "the fingers close on nothing",
            _slip,
        ),
        FaultKind(
            "blackout",
            "CAMERA [S]",
            "the logical camera reports nothing (for S seconds of the world's clock, else "
            "until `fault clear blackout`)",
            _blackout,
            lasting=False,
        ),
    )
}
"""Every kind of fault, by name, in the order docs and errors list them."""


def _kinds() -> str:
    return ", ".join(FAULT_KINDS)


def _spec(words: list[str]) -> FaultSpec:
    if not words:
        raise _bad(f"needs a fault: {_kinds()}")
    kind = FAULT_KINDS.get(words[0].lower())
    if kind is None:
        raise _bad(f"unknown fault {shown(words[0])}; faults: {_kinds()}")
    return kind.parse(words[1:])


def _time(word: str, what: str) -> float:
    values = numbers("fault", word)
    if len(values) != 1 or not 0.0 <= values[0] <= FAULT_TIME_S:
        raise _bad(f"{what} {shown(word, 12)} is not a time within 0..{FAULT_TIME_S:g} s")
    return values[0]


@verb(
    "fault",
    "[at T|after S] KIND [ARGS] | clear [KIND|all]",
    "make a fault happen on this connection's robot, now, at world time T [s] or S [s] "
    "from now: `estop`, `protective`, `stall JOINT`, `noise SIGMA`, `latency MS[,JITTER]`, "
    "`disconnect`, `drop [PART]`, `slip P` (docs/faults.md); `clear` ends one kind (or all, "
    "scheduled ones too)",
    examples=("fault estop", "fault stall joint_l", "fault at 2.5 estop", "fault clear"),
)
@dataclass(frozen=True, slots=True)
class FaultVerb:
    """Start ``spec`` (now, at clock time ``at_s`` or ``after_s`` from now), or clear
    faults (``clear``: a kind or ``all``)."""

    spec: FaultSpec | None = None
    at_s: float | None = None
    after_s: float | None = None
    clear: str | None = None

    @staticmethod
    def parse(verb: str, words: list[str]) -> FaultVerb:
        if not words:
            raise _bad(f"needs a fault: {_kinds()}")
        first = words[0].lower()
        if first == "clear":
            if len(words) > 2:
                raise _bad("clear takes at most one KIND (or all)")
            what = words[1].lower() if len(words) == 2 else "all"
            if what != "all" and what not in FAULT_KINDS:
                raise _bad(f"cannot clear {shown(words[1])}; faults: {_kinds()}, all")
            return FaultVerb(clear=what)
        if first in ("at", "after"):
            if len(words) < 2:
                raise _bad(f"{first} needs a time")
            seconds = _time(words[1], "T" if first == "at" else "S")
            spec = _spec(words[2:])
            if first == "at":
                return FaultVerb(spec, at_s=seconds)
            return FaultVerb(spec, after_s=seconds)
        return FaultVerb(_spec(words))


@verb(
    "faults",
    "",
    "reply this robot's faults: `ok none`, or `ok ` and each active one (`KIND [ARGS] since "
    "T`) and scheduled one (`KIND [ARGS] at T`), `; ` between",
    examples=("faults",),
)
@dataclass(frozen=True, slots=True)
class Faults:
    """List this robot's active and scheduled faults."""


@verb(
    "reset",
    "",
    "lift this robot's protective stop, or its emergency stop once `fault clear estop` "
    "released it; moves are accepted again",
    examples=("reset",),
)
@dataclass(frozen=True, slots=True)
class Reset:
    """Lift a stop (as a pendant's reset button)."""
