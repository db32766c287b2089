"""The edge of a joint limit: how far past it a value still counts, and how it prints.

Replies print 10 significant digits, so a value read back with ``where`` (or a
limit read with ``limits``) may sit a rounding error outside the true limit.
The server and the clients accept it with the same slack, defined here once.
A limit prints the same way everywhere (``limits``, limit errors, the page):
``limit_text``; an error prints a refused value and its limit with as many more
digits as it takes for them to differ (``texts_apart``), so a refused value
never looks inside the printed range.
No imports beyond the standard library: the clients load this too.
"""

from __future__ import annotations

__all__ = ["LIMIT_TOLERANCE", "limit_text", "texts_apart", "within_limit"]

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
