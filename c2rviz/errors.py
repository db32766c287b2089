"""One error family for everything a user can get wrong, and the edge of a joint limit.

Every error builds its own message, names what was wrong and, where there is a
finite set, the valid choices. The server turns any of these into one
``error: <message>`` reply; the command-line tools print the message and exit 2.

The edge of a joint limit is here too: how far past it a value still counts, and how it
prints. Replies print 10 significant digits, so a value read back with ``where`` (or a
limit read with ``limits``) may sit a rounding error outside the true limit; the server
and the clients accept it with the same slack, ``within_limit``. A limit prints the same
way everywhere (``limits``, limit errors, the page): ``limit_text``; an error prints a
refused value and its limit with as many more digits as it takes for them to differ
(``texts_apart``), so a refused value never looks inside the printed range.
No imports beyond the standard library: the clients load this too.
"""

from __future__ import annotations

from collections.abc import Sequence

LIMIT_TOLERANCE = 1e-9
"""Relative slack at a limit: ``1e-9 * max(1, |limit|)`` in the value's own unit."""


def within_limit(value: float, lower: float, upper: float) -> bool:
    """Whether ``value`` lies in ``[lower, upper]``, give or take the rounding slack.

    Args:
        value: The value, in the same unit as the limits ([rad], [deg] or [m]).
        lower: The lower limit (may be ``-inf``).
        upper: The upper limit (may be ``inf``).

    Returns:
        True when ``lower - slack <= value <= upper + slack``, the slack being
        ``LIMIT_TOLERANCE * max(1, |limit|)`` at each end. False for NaN.
    """
    if lower <= value <= upper:
        return True
    low = lower - LIMIT_TOLERANCE * max(1.0, abs(lower))
    high = upper + LIMIT_TOLERANCE * max(1.0, abs(upper))
    return low <= value <= high


def limit_text(limit: float) -> str:
    """A limit as ``limits``, limit errors and the page print it.

    Args:
        limit: The limit, in the unit it is shown in ([rad], [deg] or [m]).

    Returns:
        10 significant digits, no trailing zeros (``89.9999999``, ``3.1416``,
        ``-inf``); ``0`` within 1e-9 of zero, like every reply value.
    """
    return f"{limit:.10g}" if abs(limit) > 1e-9 else "0"


def texts_apart(value: float, limit: float) -> tuple[str, str]:
    """A refused ``value`` and the ``limit`` it passed, printed so that they differ.

    Both get 10 significant digits (the limit as ``limit_text``); if they print
    the same, both get more digits (up to 17, where distinct floats always
    differ). Printing is monotonic, so the value then looks as far outside as it is.

    Args:
        value: The refused value, in the limit's unit.
        limit: The limit it is beyond.

    Returns:
        ``(value_text, limit_text)``.
    """
    value_text, shown = f"{value:.10g}", limit_text(limit)
    digits = 10
    while value_text == shown and digits < 17:
        digits += 1
        value_text, shown = f"{value:.{digits}g}", f"{limit:.{digits}g}"
    return value_text, shown


def shown(text: str, limit: int = 40) -> str:
    """Return ``text`` quoted for an error message: printable, and cut if long."""
    cut = text if len(text) <= limit else text[:limit] + "..."
    return repr(cut)


class C2rvizError(Exception):
    """Root of every c2rviz error; ``str(error)`` is the message for the user."""


class LineError(C2rvizError):
    """A line that cannot be a command at all (bad bytes, control characters)."""


class LineTooLong(LineError):
    """A line over the server's length limit; the connection is closed."""

    def __init__(self, limit: int) -> None:
        self.limit = limit
        super().__init__(f"line too long (limit {limit} bytes); closing")


class UnknownCommand(C2rvizError):
    """A verb that is not in the command language."""

    def __init__(self, verb: str, close: tuple[str, ...] = ()) -> None:
        self.verb = verb
        self.close = close
        if close:
            hint = "did you mean " + " or ".join(f"'{word}'" for word in close) + "?"
        else:
            hint = "try 'help'"
        super().__init__(f"unknown command {shown(verb)} ({hint})")


class BadArguments(C2rvizError):
    """A known verb with arguments of the wrong shape."""

    def __init__(self, verb: str, problem: str, usage: str) -> None:
        self.verb = verb
        self.problem = problem
        self.usage = usage
        super().__init__(f"{verb}: {problem} (usage: {usage})")


class JointIndexError(C2rvizError):
    """A joint index outside 0..n-1 of the chain."""

    def __init__(self, index: int | str, robot: str, count: int) -> None:
        self.index = index
        self.robot = robot
        self.count = count
        shown_index = index if isinstance(index, int) else shown(index, 12)
        super().__init__(
            f"joint index {shown_index} out of range: {robot} has joints 0..{count - 1}"
        )


class JointCountError(C2rvizError):
    """A ``joints`` command whose value count differs from the chain's length."""

    def __init__(self, needed: int, got: int) -> None:
        self.needed = needed
        self.got = got
        super().__init__(f"joints needs {needed} values, got {got}")


class JointLimitError(C2rvizError):
    """A value outside a joint's limits, reported in the client's units."""

    def __init__(
        self, joint: str, index: int, value: float, lower: float, upper: float, unit: str
    ) -> None:
        self.joint = joint
        self.index = index
        self.value = value
        self.lower = lower
        self.upper = upper
        self.unit = unit
        # The limits print as `limits` prints them; the one passed, with more digits
        # if need be, so that the value never looks inside the printed range.
        if value < lower:
            value_text, low = texts_apart(value, lower)
            high = limit_text(upper)
        else:
            value_text, high = texts_apart(value, upper)
            low = limit_text(lower)
        super().__init__(
            f"{joint} (index {index}) = {value_text} {unit} is outside its limits "
            f"{low}..{high} {unit}"
        )


class RobotError(C2rvizError):
    """A robot description that cannot be loaded or has no usable chain."""


class ConfigError(C2rvizError):
    """A bad setting in cmdinterpreter.ini or on the command line."""

    def __init__(self, problem: str, choices: Sequence[str] = ()) -> None:
        self.problem = problem
        self.choices = tuple(choices)
        message = problem
        if self.choices:
            message += " (choose from: " + ", ".join(self.choices) + ")"
        super().__init__(message)


class UnknownRobot(C2rvizError):
    """A robot name that is not in the world."""

    def __init__(self, name: str, names: Sequence[str]) -> None:
        self.name = name
        self.names = tuple(names)
        super().__init__(f"no robot {shown(name)} here; robots: {', '.join(self.names)}")


class MotionInterrupted(C2rvizError):
    """A move that a waiting client will not see arrive: preempted or stopped."""

    def __init__(self, why: str) -> None:
        self.why = why
        super().__init__(why)


class PathCollides(C2rvizError):
    """A guarded command whose target, or a point of its way there, collides."""

    def __init__(
        self,
        first: str,
        second: str,
        fraction: float,
        at_target: bool,
        target: Sequence[float] | None = None,
    ) -> None:
        self.pair = (first, second)
        self.fraction = fraction
        self.target = None if target is None else tuple(target)
        """The refused command's target [rad or m], when known (the page shows it)."""
        where = "at the target" if at_target else f"at {fraction * 100:.0f}% of the move"
        super().__init__(f"{first} would hit {second} {where}")


class ArmMoved(C2rvizError):
    """A command that needs the arm where it was planned from, or at rest."""


class UnknownMarker(C2rvizError):
    """A marker number that is not among the robot's markers."""

    def __init__(self, index: int, count: int) -> None:
        self.index = index
        self.count = count
        have = f"markers 1..{count}" if count else "no markers"
        super().__init__(f"no marker {index}: this robot has {have} (1 is the oldest)")


class NoGripper(C2rvizError):
    """A gripper command for a robot that has no gripper."""

    def __init__(self, robot: str) -> None:
        self.robot = robot
        super().__init__(
            f"no gripper: {robot} has none (a gripper is finger joints in its URDF, or the "
            "ini's gripper = JOINT:CLOSED:OPEN ...)"
        )


class FaultStop(C2rvizError):
    """A move refused because a fault stopped the robot (``fault estop``, ``protective``)."""

    def __init__(self, message: str, since_s: float) -> None:
        self.since_s = since_s
        super().__init__(message)


class EmergencyStop(FaultStop):
    """A move (or ``reset``) refused during an emergency stop; ``since_s`` is the world's
    time of the stop [s since the server started]; ``released``: ``fault clear estop``
    came, and only ``reset`` is missing."""

    def __init__(self, since_s: float, released: bool) -> None:
        self.released = released
        hint = "reset to move again" if released else "fault clear estop, then reset"
        super().__init__(f"emergency stop since t={since_s:.3f} ({hint})", since_s)


class ProtectiveStop(FaultStop):
    """A move refused during a protective stop (until ``reset``)."""

    def __init__(self, since_s: float) -> None:
        super().__init__(f"protective stop since t={since_s:.3f} (reset to move again)", since_s)


class JointStalled(C2rvizError):
    """A move that needed a stalled joint (``fault stall``) to move: it ended short."""

    def __init__(self, joint: str, value: float, unit: str) -> None:
        self.joint = joint
        self.value = value
        self.unit = unit
        super().__init__(f"{joint} stalled at {value:.4g} {unit}")
