"""Parts in a live world: added and removed, grasped, carried, released, falling on the clock.

``WorldParts`` belongs to the ``World`` and is one of its observers: a robot's new joints
move the parts it holds. The session checks a command's words; this applies the rules
(``part_rules.py``: what closing fingers take) and tells every observer ``on_parts`` (the parts
now, poses in the world frame) and ``on_part_event`` (``grasped NAME``, ``released NAME``,
``resting NAME on WHAT``). Every robot's collision model gets the parts as they change.

A released part rests where it is when something lies within ``REST_TOL_M`` below it (an
object's top, a part, the floor at z = 0: it is lowered onto it); otherwise it falls
straight down, at g on the world's clock, to the first surface below. It never turns
and never passes through an object. A part resting on a part that is taken away falls.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING

import numpy as np
import pinocchio as pin

from ..collision.geometry import Obstacle, drop, extent, robot_geometry, signed_distance
from .part_rules import (
    Goal,
    GoalBook,
    GoalResult,
    at_cup,
    finger_links,
    jaws,
    opening_for,
    score,
    take,
)
from .parts import FLOOR, Falls, Part, PartError, Parts

if TYPE_CHECKING:
    from ..collision.model import CollisionModel, PartShape
    from .clock import Clock
    from .live_collisions import Contacts
    from .state import RobotState


REST_TOL_M = 0.002
"""A part put down this close above something rests on it [m]."""
OVERLAP_TOL_M = 0.001
"""A new part may sink this deep into an object or part (resting on it) [m]."""


class PartInsideObject(PartError):
    def __init__(self, name: str, other: str, depth_m: float) -> None:
        super().__init__(
            f"part {name!r} would be {depth_m * 1000:.1f} mm inside {other!r}: "
            "place it on top or beside"
        )


class WorldParts:
    """The parts of a world and the rules that move them."""

    def __init__(
        self,
        robots: dict[str, RobotState],
        contacts: Contacts,
        clock: Clock,
        frame_s: float,
        tell: Callable[..., None],
    ) -> None:
        """Set up.

        Args:
            robots: The world's robots by name.
            contacts: The world's collision models and live checks.
            clock: The world's clock.
            frame_s: Time between two frames of a falling part [s].
            tell: ``tell(method, *args)`` calls an observer method on every observer.
        """
        self.robots = robots
        self.contacts = contacts
        self.clock = clock
        self.frame_s = frame_s
        self.tell = tell
        self.parts = Parts()
        self._geometry: dict[str, pin.GeometryModel] = {}
        self._data: dict[str, pin.Data] = {}  # each robot's, for the parts it carries
        self.falls = Falls(clock, frame_s, self._rest, lambda done: self.changed(models=done))
        self.goals = GoalBook()
        self.slips: Callable[[str], bool] = lambda robot: False
        """``slips(robot)``: a grasp the rule would make fails now (``fault slip``; the
        world sets it to its faults')."""

    # --- goals ------------------------------------------------------------------------

    def set_goal(self, goal: Goal) -> None:
        """Add or replace a goal (``GoalBook.set``: a named part must exist)."""
        self.goals.set(goal, self.parts)
        self.tell("on_goals", self.goals.all())

    def remove_goal(self, key: str) -> None:
        """Remove one goal (``all``: every one)."""
        self.goals.remove(key)
        self.tell("on_goals", self.goals.all())

    def score(self) -> list[GoalResult]:
        return score(self.goals.all(), self.parts.all())

    # --- what is around --------------------------------------------------------------

    def obstacles(self, but: str = "") -> list[Obstacle]:
        """Every object of every built workcell, and every part no robot holds (but
        ``but``), placed in the world."""
        found: list[Obstacle] = []
        for name, state in self.robots.items():
            model = self.contacts.models.get(name)
            if model is None:
                continue
            for obj, shape in model.workcell.items():
                found.append((obj.name, shape, state.base * obj.placement))
        for part in self.parts.all():
            if part.name != but and part.holder is None and not part.falling:
                found.append((part.name, part.geometry, part.pose))
        return found

    # --- edits -----------------------------------------------------------------------

    def add(
        self,
        name: str,
        shape: str,
        size: Sequence[float],
        pose: pin.SE3,
        kind: str | None = None,
        rgba: Sequence[float] | None = None,
    ) -> Part:
        """Add a part at ``pose`` (world frame), checked; it stays where it is put.

        Raises:
            PartError: a name in use, a bad size, too many parts, or a part inside an
                object or another part; nothing changes.
        """
        taken: set[str] = set()
        for robot in self.robots:
            model = self.contacts.models.get(robot)
            taken.update(model.objects() if model is not None else ())
            taken.update(self.robots[robot].robot.link_names())
        part = self.parts.make(name, shape, size, pose, kind, rgba, taken)
        for other, geometry, where in self.obstacles():
            depth = -signed_distance(part.geometry, part.pose, geometry, where)
            if depth > OVERLAP_TOL_M:
                raise PartInsideObject(name, other, depth)
        self.parts.add(part)
        down, onto = self._drop(part)
        part.on = onto if down <= REST_TOL_M else None
        self.changed()
        return part

    def remove(self, name: str) -> None:
        """Remove one part (``all``: every one)."""
        gone = self.parts.clear() if name == "all" else [self.parts.remove(name)]
        for part in gone:
            self.falls.cancel(part.name)
        for part in gone:
            self._unsupport(part.name)
        self.changed()

    # --- grasp and release -------------------------------------------------------------

    def close(self, robot: str, opening_now: float, target: float) -> tuple[float, Part | None]:
        """Robot ``robot``'s fingers close from ``opening_now`` to ``target``: the part they
        take by the rule (and the opening where they stop on it), or (target, None)."""
        state = self.robots[robot]
        gripper = state.robot.gripper
        if gripper is None or self.parts.held_by(robot):
            return target, None
        found = jaws(state.robot, self._fingers(robot), state.origin, state.q, opening_now)
        if found is None:
            return target, None
        candidates = [p for p in self.parts.all() if p.holder != robot]
        part = take(found, gripper, target, candidates)
        if part is None or self._slipped(robot, part):
            return target, None
        half = extent(part.obj.shape, part.obj.size, part.pose.rotation, found.axis)
        along = float((part.pose.translation - found.centre) @ found.axis)
        part.pose = pin.SE3(part.pose.rotation, part.pose.translation - along * found.axis)
        self.hold(robot, part, gripper.name)
        return max(opening_for(gripper, 2.0 * half), target), part

    def suck(self, robot: str) -> Part | None:
        """Robot ``robot``'s vacuum cup (its tool point) turns suction on: it takes the part
        whose surface is within ``CUP_M`` of it, if any."""
        state = self.robots[robot]
        if self.parts.held_by(robot):
            return None
        cup = state.base * state.robot.ee_pose(state.q) * state.tool
        part = at_cup(cup, [p for p in self.parts.all() if p.holder != robot])
        if part is None or self._slipped(robot, part):
            return None
        self.hold(robot, part, state.robot.eelink)
        return part

    def _slipped(self, robot: str, part: Part) -> bool:
        """The grasp of ``part`` fails (``fault slip``): say so, take nothing."""
        if not self.slips(robot):
            return False
        self.tell("on_part_event", robot, f"slipped {part.name}")
        return True

    def hold(self, robot: str, part: Part, link: str) -> None:
        """Fix ``part`` to ``robot``'s ``link`` where it is (taking it from whoever had it)."""
        state = self.robots[robot]
        model = state.robot.model
        data = model.createData()
        pin.framesForwardKinematics(model, data, state.robot.configuration(state.q))
        link_pose = state.origin * data.oMf[model.getFrameId(link)]
        part.holder, part.link, part.on = robot, link, None
        part.offset = link_pose.inverse() * part.pose
        self.falls.cancel(part.name)
        self.tell("on_part_event", robot, f"grasped {part.name}")
        self._unsupport(part.name)
        self.changed()

    def release(self, robot: str, only: str | None = None) -> list[Part]:
        """Robot ``robot`` lets go of what it holds (``only``: of that part, if it holds
        it): each part rests or falls."""
        let_go = [p for p in self.parts.held_by(robot) if only is None or p.name == only]
        for part in let_go:
            part.holder = part.link = None
            self.tell("on_part_event", robot, f"released {part.name}")
            self._settle(part)
        if let_go:
            self.changed()
        return let_go

    def _settle(self, part: Part) -> None:
        down, onto = self._drop(part)
        if down <= REST_TOL_M:
            self._lower(part, down)
            self._rest(part, onto)
        else:
            self.falls.start(part, down, onto)

    def _rest(self, part: Part, onto: str) -> None:
        part.falling, part.on = False, onto
        self.tell("on_part_event", None, f"resting {part.name} on {onto}")

    def objects_changed(self) -> None:
        """The workcell changed: a part resting on an object that is gone settles again."""
        there = {name for name, _, _ in self.obstacles()} | {FLOOR}
        for part in self.parts.all():
            if part.on is not None and part.on not in there and not part.falling:
                self._unsupport_part(part)
        self.changed()

    def _unsupport_part(self, part: Part) -> None:
        part.on = None
        self._settle(part)

    def _unsupport(self, name: str) -> None:
        """Parts resting on ``name`` (taken or removed) settle again."""
        for part in self.parts.all():
            if part.on == name and part.holder is None and not part.falling:
                part.on = None
                self._settle(part)

    def _drop(self, part: Part) -> tuple[float, str]:
        return drop(
            part.obj.shape,
            part.obj.size,
            part.geometry,
            part.pose,
            self.obstacles(but=part.name),
            FLOOR,
        )

    @staticmethod
    def _lower(part: Part, down: float) -> None:
        part.pose = pin.SE3(part.pose.rotation, part.pose.translation - np.array([0, 0, down]))

    # --- following the arms ----------------------------------------------------------

    def moved(self, robot: str, q: Sequence[float]) -> None:
        """Robot ``robot`` is now at ``q``: the parts it holds follow its link."""
        held = self.parts.held_by(robot)
        if not held:
            return
        state = self.robots[robot]
        model = state.robot.model
        data = self._data.get(robot)
        if data is None:
            data = self._data[robot] = model.createData()
        pin.forwardKinematics(model, data, state.robot.configuration(q))
        for part in held:
            assert part.link is not None
            frame = model.getFrameId(part.link)
            link = pin.updateFramePlacement(model, data, frame)
            part.pose = state.origin * link * part.offset
        self.changed(models=False)

    def stop(self) -> None:
        self.falls.stop()

    # --- telling ----------------------------------------------------------------------

    def changed(self, models: bool = True) -> None:
        """Tell the observers the parts now; with ``models``, the collision models too."""
        if models:
            for robot, model in self.contacts.models.items():
                self.furnish(robot, model)
                self.contacts.changed(robot)
        self.tell("on_parts", self.parts.all(), self.clock.now())

    def furnish(self, robot: str, model: CollisionModel) -> None:
        """Give ``robot``'s collision model the parts as they are now."""
        state = self.robots[robot]
        to_root = state.origin.inverse()
        touch = finger_links(state.robot)
        shapes: list[PartShape] = []
        for part in self.parts.all():
            if part.holder is None:
                shapes.append((part.name, part.checked, to_root * part.pose, None, touch))
            elif part.holder == robot:
                shapes.append((part.name, part.checked, part.offset, part.link, touch))
        other_touch = frozenset(
            f"{name}/{link}"
            for name, other in self.robots.items()
            if name != robot
            for link in finger_links(other.robot)
        )
        names = frozenset(self.parts.names())
        model.set_parts(shapes, touch, names, other_touch)

    def _fingers(self, robot: str) -> pin.GeometryModel:
        geometry = self._geometry.get(robot)
        if geometry is None:
            geometry = self._geometry[robot] = robot_geometry(self.robots[robot].robot)[0]
        return geometry
