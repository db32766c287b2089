"""How far past a joint limit a value may be and still count as at the limit.

Replies print 10 significant digits, so a value read back with ``where`` (or a
limit read with ``limits``) may sit a rounding error outside the true limit.
The server and the clients accept it with the same slack, defined here once.
No imports beyond the standard library: the clients load this too.
"""

from __future__ import annotations

__all__ = ["LIMIT_TOLERANCE", "within_limit"]

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
