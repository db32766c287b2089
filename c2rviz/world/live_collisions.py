"""Which pairs collide as the arms are shown, told to the observers when it changes.

``Contacts`` belongs to the ``World``. Each robot's ``CollisionModel`` (coal,
through Pinocchio) is built the first time something needs it — a workcell
object, ``collisions``, ``guard on``, or the program's start — and from then on
every published pose marks the robot for a check, run at most once per frame
on the asyncio loop: a flood of ``joints`` lines costs one check per frame, not
one per line. A change of the colliding pairs reaches the observers as
``on_collisions(robot, pairs)`` (the page turns links red, a watch stream says
``event collision ...``). In a cell, a robot's pairs include those with the other
robots as they are shown (``link_t~right/link_4``: this robot's link, then the
other robot's name and link), and a robot's move re-checks every robot.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence

from ..collision.model import CollisionModel, Pair
from ..collision.other_robots import pairs_between
from ..collision.workcell import MAX_OBJECTS
from .clock import Clock, Timer
from .observer import Observer
from .state import RobotState


class Contacts(Observer):
    """The colliding pairs of every robot whose collision model is built."""

    def __init__(
        self,
        states: dict[str, RobotState],
        tell: Callable[[str, list[Pair]], None],
        clock: Clock,
        frame_s: float,
        disabled: dict[str, Sequence[Pair]] | None = None,
        max_objects: int = MAX_OBJECTS,
    ) -> None:
        """Set up.

        Args:
            states: The world's robots by name.
            tell: Fans a robot's new colliding pairs out to the observers.
            clock: The world's clock.
            frame_s: Shortest time between two checks of a robot [s].
            disabled: Pairs never checked, by robot (from an SRDF).
            max_objects: Most workcell objects per robot.
        """
        self.states = states
        self.tell = tell
        self.clock = clock
        self.frame_s = frame_s
        self.disabled = disabled or {}
        self.max_objects = max_objects
        self.models: dict[str, CollisionModel] = {}
        self.pairs: dict[str, list[Pair]] = {}
        self._dirty: set[str] = set()
        self._timer: Timer | None = None
        self.furnish: Callable[[str, CollisionModel], None] | None = None
        """Gives a model built here the world's parts (the world's ``WorldParts``)."""

    def model(self, robot: str) -> CollisionModel:
        """The robot's collision model, built on first use (~10 ms for a bundled arm)."""
        model = self.models.get(robot)
        if model is None:
            state = self.states[robot]
            model = CollisionModel(
                state.robot, disabled=self.disabled.get(robot, ()), max_objects=self.max_objects
            )
            self.models[robot] = model
            if self.furnish is not None:
                self.furnish(robot, model)
            self.pairs[robot] = []
            self.changed(robot)
        return model

    def now(self, robot: str) -> list[Pair]:
        """The colliding pairs as the robot is shown now (checked now if due)."""
        if robot in self._dirty or robot not in self.models:
            self.model(robot)
            self._check([robot])
        return self.pairs[robot]

    def changed(self, robot: str) -> None:
        """The robot's pose or its workcell changed: check it within a frame."""
        self._dirty.add(robot)
        if self._timer is None:
            try:
                self._timer = self.clock.call_later(self.frame_s, self._due)
            except RuntimeError:
                return  # no loop (a model used off the loop): checked when asked

    def stop(self) -> None:
        if self._timer is not None:
            self._timer.cancel()
            self._timer = None

    def on_joints(self, robot: str, q: Sequence[float], t: float) -> None:
        if len(self.states) > 1:  # its pairs with the other robots change too
            for name in self.models:
                self.changed(name)
        elif robot in self.models:
            self.changed(robot)

    def _due(self) -> None:
        self._timer = None
        self._check(list(self._dirty))

    def _check(self, robots: Iterable[str]) -> None:
        for robot in robots:
            self._dirty.discard(robot)
            state = self.states[robot]
            pairs = self.models[robot].colliding(state.q)
            if len(self.states) > 1:
                others = [
                    (name, self.model(name), other.q, other.origin)
                    for name, other in self.states.items()
                    if name != robot
                ]
                pairs = sorted(
                    pairs + pairs_between(self.models[robot], state.origin, state.q, others)
                )
            if pairs != self.pairs[robot]:
                self.pairs[robot] = pairs
                self.tell(robot, pairs)
