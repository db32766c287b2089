"""A session's lasting modes, and the setters through which a door changes them.

A door never assigns a session's fields: it calls these (``tests/app/test_one_way_in``
keeps it so); the text verbs' handlers set the same fields (``motion``, ``speed``,
``lspeed``, ``guard``).
"""

from __future__ import annotations

__all__ = ["Modes"]


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
