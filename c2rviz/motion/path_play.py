"""A joint path played on the caller's clock: what a move along a path must offer the world.

A straight tool line (``line_play.LinePlay``), a planned path around obstacles
(``planning.timing.TimedPath``) and a timed trajectory from a door are each a
``PathPlay``: sampled at the clock's time, ending at rest at a known time, and
able to brake to rest *on* its path (never leaving the path it was checked along).
"""

from __future__ import annotations

from typing import Protocol

__all__ = ["PathPlay"]


class PathPlay(Protocol):
    """A joint path with its timing, on the caller's clock [s]."""

    @property
    def arrival(self) -> float:
        """When the path comes to rest [s]."""
        ...

    def sample(self, t: float) -> tuple[float, ...]:
        """The chain's values at time ``t`` [s] (at rest at the end after ``arrival``)."""
        ...

    def brake(self, t: float) -> float:
        """From time ``t`` [s] slow down to rest on the path as fast as the limits allow;
        return the new arrival [s]."""
        ...
