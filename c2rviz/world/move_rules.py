"""What faults make of moves: the hooks ``Travels`` asks (``fault_rules.FaultRules``
fills them in); the base changes nothing."""

from __future__ import annotations

from ..errors import C2rvizError
from .state import RobotState

__all__ = ["MoveRules"]


class MoveRules:
    """What faults make of moves; this base changes nothing."""

    def refuse(self, state: RobotState) -> None:
        """Raise if a move of ``state`` is refused now."""

    def follow(self, state: RobotState, q: tuple[float, ...]) -> tuple[float, ...]:
        """Where ``state``'s joints are when commanded to ``q``."""
        return q

    def arrival_error(self, state: RobotState) -> C2rvizError | None:
        """The error a move that came to rest at its target ends with (None: ``ok``)."""
        return None
