"""How sessions start, what they keep, and what one client may cost.

``ServerLimits`` bound what one client of a door may cost (README: "Limits");
``SessionDefaults`` say how a new session starts (each may change its own with a
command). Both are plain settings the app fills in from ``cmdinterpreter.ini`` and the
flags (``app.config``).

``Modes`` are a session's lasting modes, and the setters through which a door changes
them: a door never assigns a session's fields, it calls these (``tests/app/test_one_way_in``
keeps it so); the text verbs' handlers set the same fields (``motion``, ``speed``,
``lspeed``, ``guard``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..protocol.limits import default, default_s


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


class Modes:
    """The modes a ``session.Session`` keeps between commands (see its attributes)."""

    source: str
    motion: str
    speed: float
    lspeed: float
    guard: bool
    plan_around: bool
    hangup: str | None

    def set_source(self, source: str) -> None:
        """Name who speaks as ``source`` from now on (a connection, once its peer is known)."""
        self.source = source

    def take_hangup(self) -> str | None:
        """The hangup a handler asked for (``bye``, ``quit`` or None), cleared."""
        hangup, self.hangup = self.hangup, None
        return hangup

    def set_motion(self, mode: str) -> None:
        """Move ``off`` (at once), ``on`` (replies on arrival) or ``follow`` from now on."""
        self.motion = mode

    def set_speed(self, percent: float) -> None:
        """Move at ``percent`` of the joints' limits from now on."""
        self.speed = percent

    def set_lspeed(self, m_s: float) -> None:
        """Straight lines at ``m_s`` [m/s] from now on."""
        self.lspeed = m_s

    def set_guard(self, on: bool, plan_around: bool = False) -> None:
        """Refuse (``plan_around``: plan around) what would collide, from now on."""
        self.guard = on
        self.plan_around = on and plan_around
