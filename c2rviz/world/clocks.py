"""Which clock: ``parse_clock`` reads ``--clock`` (``real``, ``scaled:N``, ``virtual``)."""

from __future__ import annotations

import math

from ..errors import ConfigError
from .clock import Clock, ScaledClock
from .virtual_clock import VirtualClock

__all__ = ["CLOCK_FORMS", "parse_clock"]

CLOCK_FORMS = ("real", "scaled:N", "virtual")
"""What ``--clock`` accepts (N: a finite number above 0, the clock seconds per real second)."""


def parse_clock(text: str, name: str = "--clock") -> Clock:
    """The clock ``--clock TEXT`` names: ``real``, ``scaled:N`` or ``virtual``.

    Args:
        text: The clock's form.
        name: Where it was given, for the message (``--clock``, ``[options] clock``).

    Raises:
        ConfigError: any other text, a factor that is not a finite number above 0
            (``scaled:0``, negative, ``nan``, ``inf``), naming the valid forms.
    """
    word = text.strip().lower()
    if word == "real":
        return Clock()
    if word == "virtual":
        return VirtualClock()
    kind, colon, number = word.partition(":")
    if kind == "scaled" and colon:
        try:
            factor = float(number)
        except ValueError:
            factor = math.nan
        if math.isfinite(factor) and factor > 0:
            return ScaledClock(factor)
        raise ConfigError(
            f"{name} {text}: the factor must be a finite number above 0 "
            "(scaled:10 runs ten times faster)",
            CLOCK_FORMS,
        )
    raise ConfigError(f"{name} {text!r} is not a clock", CLOCK_FORMS)
