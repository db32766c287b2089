"""Collisions: the robot against itself and against the workcell, with coal.

The geometry is ``geometry.robot_geometry`` (URDF collision elements,
visual ones where a link has none, on the full model). Which link pairs are
checked is settled once, at construction, as MoveIt's setup assistant does:
never links joined by a joint (a link without geometry passes its neighbours
on), pairs an SRDF disables, pairs that cannot move relative to each other,
pairs that touch at home (each chain joint at 0, or its nearest limit), and
pairs that touch in nearly every one of ``samples`` random configurations (a
fixed seed, so the choice is reproducible): ``checks.choose_pairs``. Pairs that never
touched in the samples are still checked. Workcell objects (``workcell.py``) are checked
against every link the chain moves; a link that never moves relative to the
base (the pedestal a table touches) never collides with them.

A pair is ``(link, link)`` in alphabetical order, or ``(link, object)``.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin

from ..robot.model import Robot
from .batch import BatchCheck, CheckGeometry, PlacedShape
from .checks import (
    DEFAULT_SAMPLES,
    PartShape,
    build_checks,
    choose_pairs,
    held_as_links,
    held_shapes,
    hits,
)
from .geometry import CollisionError, Pair, moving_joints, ordered_pair, robot_geometry
from .workcell import MAX_OBJECTS, Workcell, WorkcellObject

MAX_STEP_RAD = math.radians(1.0)  # guarded paths: most a revolute joint moves between checks
MAX_STEP_M = 0.005  # and a prismatic one


class NoFreeConfiguration(CollisionError):
    """No collision-free configuration in the bounded number of random draws."""

    def __init__(self, robot: str, tries: int, always: Sequence[Pair] = ()) -> None:
        self.robot = robot
        self.tries = tries
        self.always = tuple(always)
        """Pairs touching in every draw looked at: a contact no joint can undo."""
        found = f"no collision-free configuration of {robot} found in {tries} random draws"
        if self.always:
            first, second = self.always[0]
            super().__init__(
                f"{found}: {first} touches {second} in every pose tried, a contact no "
                f"joint undoes (an object through the robot's base? move or remove it)"
            )
        else:
            super().__init__(
                f"{found} (the workcell may fill its reach; remove objects or turn the guard off)"
            )


def segment(
    robot: Robot,
    q0: Sequence[float],
    q1: Sequence[float],
    max_step_rad: float = MAX_STEP_RAD,
    max_step_m: float = MAX_STEP_M,
) -> list[tuple[float, ...]]:
    """Points from ``q0`` to ``q1`` (both included), straight in joint space.

    Consecutive points differ by at most ``max_step_rad`` on a revolute joint
    and ``max_step_m`` on a prismatic one, so a thin link cannot pass through
    an object between two checks.
    """
    a = np.asarray(q0, dtype=float)
    delta = np.asarray(q1, dtype=float) - a
    steps = np.where(robot.prismatic, max_step_m, max_step_rad)
    count = max(1, math.ceil(float(np.max(np.abs(delta) / steps, initial=0.0)) - 1e-9))
    return [tuple((a + delta * (k / count)).tolist()) for k in range(count + 1)]


class CollisionModel:
    """The robot's collision geometry, the pairs checked, and the workcell.

    Attributes:
        robot: The robot (configurations come from ``robot.configuration``).
        self_pairs: Which link pairs are checked, and why the others are not.
        workcell: The objects (read it for drawing; change it through the
            methods here so the checks follow).
        warnings: Meshes dropped or kept as triangles, SRDF links unknown.
    """

    def __init__(
        self,
        robot: Robot,
        *,
        disabled: Iterable[Pair] = (),
        samples: int = DEFAULT_SAMPLES,
        seed: int = 0,
        max_objects: int = MAX_OBJECTS,
        convex: bool = True,
    ) -> None:
        """Build the geometry and choose the self-collision pairs (see the module).

        Args:
            robot: The robot.
            disabled: Link pairs never to check (an SRDF's, see ``read_srdf``).
            samples: Random configurations drawn to find always-touching pairs.
            seed: Seed of those draws, so the pairs chosen are reproducible.
            max_objects: Most workcell objects at once.
            convex: Check robot meshes by their convex hulls (quicker, a little larger).

        Raises:
            CollisionModelError: the URDF's collision geometry cannot be built.
        """
        self.robot = robot
        self.model = robot.model
        self.data = robot.model.createData()
        geometry, notes = robot_geometry(robot, convex)
        self._geometry = geometry
        self._link_of = [self.model.frames[g.parentFrame].name for g in geometry.geometryObjects]
        self._links = frozenset(self._link_of)
        moving = moving_joints(robot)
        self._moving_geoms = [
            i for i, g in enumerate(geometry.geometryObjects) if g.parentJoint in moving
        ]
        known = set(robot.link_names())
        skip = {ordered_pair(*pair) for pair in disabled}
        unknown = sorted({name for pair in skip for name in pair} - known)
        if unknown:
            notes.append(f"disabled pairs name links {robot.name} lacks: {', '.join(unknown)}")
        self.warnings = tuple(notes)
        self.self_pairs = choose_pairs(robot, geometry, self._link_of, skip, moving, samples, seed)
        self.workcell = Workcell(known, max_objects)
        self._parts: tuple[PartShape, ...] = ()
        self._touching: tuple[frozenset[str], frozenset[str], frozenset[str]] = (
            frozenset(),
            frozenset(),
            frozenset(),
        )  # its fingers, every part's name, the other robots' fingers (``set_parts``)
        self._revision = 0
        self._rebuild()

    def _rebuild(self) -> None:
        self._checks = geometry, data, names = build_checks(
            self.robot,
            self._geometry,
            self._link_of,
            self._moving_geoms,
            set(self.self_pairs.checked),
            self.workcell.items(),
            parts=self._parts,
        )
        self._revision += 1
        moving, link_of = held_as_links(geometry, self._moving_geoms, self._link_of)
        self._snapshot = CheckGeometry(  # one assignment: another thread reads it whole
            geometry,
            data,
            tuple(names),
            moving,
            link_of,
            self._revision,
            *self._touching,
        )

    # --- for checkers of one's own -----------------------------------------------

    @property
    def revision(self) -> int:
        """Counts the changes of what is checked (each object set or removed)."""
        return self._snapshot.revision

    def check_geometry(self) -> CheckGeometry:
        """What is checked now, for a checker of one's own (``batch_check``); it stays
        valid (a change builds new checks, it never alters these)."""
        return self._snapshot

    def batch_check(
        self,
        others: Sequence[PlacedShape] = (),
        *,
        origin: pin.SE3 | None = None,
        without: Iterable[Pair] = (),
        only: Iterable[Pair] | None = None,
    ) -> BatchCheck:
        """A fast batched check of this robot for one thread (``batch.BatchCheck``): its
        pairs and objects now, the ``others`` (other robots' shapes placed in the cell,
        this robot's root at ``origin``) as fixed obstacles, less ``without`` or only
        ``only``."""
        return BatchCheck(
            self.robot,
            self.check_geometry(),
            others,
            origin=origin,
            without=frozenset(without),
            only=None if only is None else frozenset(only),
        )

    # --- the workcell -----------------------------------------------------------

    def set_object(
        self,
        name: str,
        shape: str,
        size: Sequence[float],
        placement: pin.SE3,
        rgba: Sequence[float] | None = None,
        mesh_path: str | Path | None = None,
    ) -> WorkcellObject:
        """Add or replace an object, placed in the base frame (``Workcell.set``)."""
        obj = self.workcell.set(name, shape, size, placement, rgba, mesh_path)
        self._rebuild()
        return obj

    def remove_object(self, name: str) -> None:
        """Remove one object (raises ``UnknownObject``)."""
        self.workcell.remove(name)
        self._rebuild()

    def remove_all(self) -> None:
        """Remove every object."""
        self.workcell.clear()
        self._rebuild()

    def set_parts(
        self,
        parts: Sequence[PartShape],
        touch: frozenset[str] = frozenset(),
        names: frozenset[str] = frozenset(),
        other_touch: frozenset[str] = frozenset(),
    ) -> None:
        """The parts now (``checks.add_parts`` says how each is checked); ``touch``:
        this robot's links that may touch parts, ``names``: every part's (those other
        robots hold too), ``other_touch``: the other robots' links that may touch a part
        (as ``robot/link``)."""
        if not parts and not self._parts and not names and not self._touching[1]:
            return  # no parts before or after: the checks (and revision) stay
        self._parts = tuple(parts)
        self._touching = (touch, names, other_touch)
        self._rebuild()

    @property
    def touching(self) -> tuple[frozenset[str], frozenset[str], frozenset[str]]:
        """Its fingers, the parts' names, the other robots' fingers (``set_parts``)."""
        return self._touching

    def objects(self) -> list[str]:
        """The objects' names, in the order they were first set."""
        return self.workcell.names()

    def object_list(self) -> list[WorkcellObject]:
        """Every object with its shape, size, placement and colour (for drawing)."""
        return [obj for obj, _ in self.workcell.items()]

    # --- checks -----------------------------------------------------------------

    def colliding(self, q: Sequence[float]) -> list[Pair]:
        """The pairs in collision at chain values ``q`` [rad or m], sorted."""
        return sorted(hits(self.model, self.data, *self._checks, self.robot.configuration(q)))

    def is_free(self, q: Sequence[float]) -> bool:
        """True when no checked pair collides at ``q`` (stops at the first hit)."""
        geometry, data, _ = self._checks
        config = self.robot.configuration(q)
        return not pin.computeCollisions(self.model, self.data, geometry, data, config, True)

    def first_collision(self, path: Iterable[Sequence[float]]) -> tuple[int, Pair] | None:
        """The index of the first point of ``path`` in collision and its first pair."""
        for index, q in enumerate(path):
            if not self.is_free(q):
                return index, self.colliding(q)[0]
        return None

    def first_collision_on_segment(
        self,
        q0: Sequence[float],
        q1: Sequence[float],
        max_step_rad: float = MAX_STEP_RAD,
        max_step_m: float = MAX_STEP_M,
    ) -> tuple[float, Pair] | None:
        """How far (0..1) along the joint-space segment q0 -> q1 it first collides."""
        points = segment(self.robot, q0, q1, max_step_rad, max_step_m)
        hit = self.first_collision(points)
        return None if hit is None else (hit[0] / (len(points) - 1), hit[1])

    def random_free(self, rng: np.random.Generator, tries: int = 1000) -> list[float]:
        """A random configuration within the limits that collides with nothing.

        Raises:
            NoFreeConfiguration: none in ``tries`` draws.
        """
        for _ in range(tries):
            q = self.robot.random(rng)
            if self.is_free(q):
                return q
        raise NoFreeConfiguration(self.robot.name, tries)

    def link_shapes(self, q: Sequence[float]) -> list[tuple[str, Any, pin.SE3]]:
        """Every collision shape of the robot at chain values ``q``: its link, its coal
        geometry and its placement in the model's root frame (for checks against
        another robot, ``other_robots.py``)."""
        geometry = self._geometry
        data = geometry.createData()  # its own data: safe beside checks on another thread
        model_data = self.model.createData()
        pin.updateGeometryPlacements(
            self.model, model_data, geometry, data, self.robot.configuration(q)
        )
        shapes = [
            (link, obj.geometry, data.oMg[k].copy())
            for k, (link, obj) in enumerate(zip(self._link_of, geometry.geometryObjects))
        ]
        return shapes + held_shapes(self.model, model_data, self._parts)

    def links_in(self, pairs: Iterable[Pair]) -> list[str]:
        """The robot links among ``pairs`` (to highlight), sorted."""
        return sorted({name for pair in pairs for name in pair if name in self._links})
