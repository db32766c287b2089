"""How sessions start and what one client may cost: plain settings the app fills in.

``ServerLimits`` bound what one client of a door may cost (README: "Limits");
``SessionDefaults`` say how a new session starts (each may change its own with a
command). Both come from ``cmdinterpreter.ini`` and the flags (``app.config``).
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["ServerLimits", "SessionDefaults"]


@dataclass(frozen=True)
class ServerLimits:
    """What one client may cost the server (README: "Limits")."""

    max_line: int = 8192
    """Longest line [bytes]; longer closes the connection."""
    max_clients: int = 64
    """Clients connected at once; one more is told so and closed."""
    max_unread: int = 1 << 20
    """Replies a client has not read [bytes]; more closes the connection."""
    partial_timeout_s: float = 10.0
    """How long a started line may stay unfinished [s]."""
    max_sleep_s: float = 3600.0
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
