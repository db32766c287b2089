"""Values the page's own controls set (a plot's window, the timeline's time and speed),
checked like every page value: one out of range is refused with a message naming the range,
and the control goes back to the true value."""

from __future__ import annotations

import math

from ..errors import C2rvizError

__all__ = ["PageValueError", "within"]


class PageValueError(C2rvizError):
    """A page control set to a value it does not take."""

    def __init__(self, control: str, value: float, valid: str) -> None:
        self.control = control
        self.value = value
        self.valid = valid
        super().__init__(f"{control} {value:g} is not {valid}")


def within(control: str, value: float, low: float, high: float, unit: str = "") -> float:
    """``value`` if it is a finite number in ``low..high``.

    Raises:
        PageValueError: naming ``control`` and the range (in ``unit``).
    """
    if not (math.isfinite(value) and low <= value <= high):
        raise PageValueError(control, value, f"within {low:g}..{high:g}{unit}")
    return float(value)
