"""How sessions start and what one client may cost: plain settings the app fills in.

``ServerLimits`` bound what one client of a door may cost (README: "Limits");
``SessionDefaults`` say how a new session starts (each may change its own with a
command). Both come from ``cmdinterpreter.ini`` and the flags (``app.config``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..protocol.limits import default, default_s

__all__ = ["ServerLimits", "SessionDefaults"]


@dataclass(frozen=True)
class ServerLimits:
    """What one client of the text port may cost the server (README: "Limits"); the
    defaults and bounds are the ``text`` rows of ``limits.LIMITS``."""

    max_line: int = default("text", "max_line")
    """Longest line [bytes]; longer closes the connection."""
    max_clients: int = default("text", "max_clients")
    """Clients connected at once; one more is told so and closed."""
    max_unread: int = default("text", "max_unread")
    """Replies a client has not read [bytes]; more closes the connection."""
    partial_timeout_s: float = default_s("text", "partial_timeout_s")
    """How long a started line may stay unfinished [s]."""
    max_sleep_s: float = default_s("text", "max_sleep_s")
    """Longest ``sleep`` [s]."""


@dataclass(frozen=True)
class SessionDefaults:
    """How a new connection starts (each may change its own with a command)."""

    motion: str = "off"
    """``off`` (moves shown at once, the seed's way), ``on`` or ``follow``."""
    speed: float = 50.0
    """Moves at this % of each joint's velocity limit (1..100)."""
    guard: bool = False
    """Refuse commands whose target or path collides."""
    lspeed: float = 0.25
    """``movel``'s tool speed [m/s] (as UR's movel)."""
    plan_around: bool = False
    """With the guard: plan around what a joint-space move's straight path would hit
    (``guard plan``) instead of refusing it."""
    plan_timeout_s: float = 1.0
    """Most time a plan searches [s] (``plan``, ``guard plan``)."""
    plan_seed: int | None = None
    """The planner's seed, so a run repeats (None: a fresh one each plan)."""
    plan_step_rad: float = math.radians(1.0)
    """Most a revolute joint moves between two checks of a path [rad] (5 mm prismatic)."""
    plan_tool_step_m: float | None = 0.005
    """Most the tool travels between two checks of a path [m]; None: no bound."""
