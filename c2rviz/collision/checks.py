"""The geometry models that do the checking, and which of a robot's link pairs they check.

``build_checks`` makes a coal geometry model of the robot's shapes that checks the given
link pairs, the workcell objects against every moving link, and the parts
(``add_parts``); ``hits`` says which of its pairs collide at a
configuration. ``choose_pairs`` settles, once per robot, which link pairs are worth
checking, as MoveIt's setup assistant does (``model.py`` says how).

Parts are in a robot's collision checks as MoveIt checks its attached objects. A part no
robot holds is an obstacle, placed in the model's root frame, checked against
every link the chain moves but the links it may touch (the fingers: they are checked
where the URDF's neutral pose puts them, not at their opening). A part this robot holds
is fixed to its gripper's link and checked against every link of the robot except those
fixed to that link and the ones it may touch, against the workcell's objects and against
the free parts; ``held_as_links`` makes a ``BatchCheck`` check it against the other
robots of a cell too, and ``held_shapes`` shows it to them. Between robots, a robot's
fingers and a part another one holds may touch (``batch.may_touch``: a hand-over). A
pair with a part is ``(link, part)``, ``(part, object)`` or ``(part, other_part)``.
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Sequence
from itertools import combinations
from typing import Any

import coal
import numpy as np
import pinocchio as pin

from ..robot.model import Robot
from .geometry import Pair, SelfPairs, adjacent_links, configure_requests, ordered_pair
from .workcell import WorkcellObject

DEFAULT_SAMPLES = 2000
ALWAYS_FRACTION = 0.95  # touching in at least this share of the samples: "always touching"

Checks = tuple[pin.GeometryModel, pin.GeometryData, list[Pair]]
"""A geometry model, its data, and the name of each of its collision pairs."""


def build_checks(
    robot: Robot,
    shapes: pin.GeometryModel,
    link_of: Sequence[str],
    moving_geoms: Sequence[int],
    link_pairs: set[Pair],
    objects: Sequence[tuple[WorkcellObject, coal.CollisionGeometry]] = (),
    exact: bool = True,
    parts: Sequence[PartShape] = (),
) -> Checks:
    """A geometry model of ``shapes`` (the robot's, ``link_of`` naming each one's link)
    checking ``link_pairs`` and the objects (placed in the base frame) against the
    ``moving_geoms`` (and ``parts``: see ``add_parts``); ``exact``: distances
    to the micrometre (``geometry.configure_requests``)."""
    model = robot.model
    geometry = pin.GeometryModel()
    names = []
    for obj in shapes.geometryObjects:
        geometry.addGeometryObject(obj)
    for i, j in combinations(range(len(link_of)), 2):
        pair = ordered_pair(link_of[i], link_of[j])
        if pair in link_pairs:
            geometry.addCollisionPair(pin.CollisionPair(i, j))
            names.append(pair)
    base = model.frames[robot.base_frame]
    for obj, shape in objects:
        k = geometry.addGeometryObject(
            pin.GeometryObject(
                f"workcell/{obj.name}",
                base.parentJoint,
                robot.base_frame,
                base.placement * obj.placement,
                shape,
            )
        )
        for i in moving_geoms:
            geometry.addCollisionPair(pin.CollisionPair(i, k))
            names.append((link_of[i], obj.name))
    if parts:
        add_parts(model, geometry, names, list(link_of), list(moving_geoms), parts)
    data = geometry.createData()
    configure_requests(data, exact)
    return geometry, data, names


def hits(
    model: pin.Model,
    model_data: pin.Data,
    geometry: pin.GeometryModel,
    data: pin.GeometryData,
    names: list[Pair],
    q: np.ndarray,
) -> set[Pair]:
    """The pairs of a ``build_checks`` model in collision at configuration ``q``."""
    if not pin.computeCollisions(model, model_data, geometry, data, q, False):
        return set()
    return {names[k] for k, result in enumerate(data.collisionResults) if result.isCollision()}


def choose_pairs(
    robot: Robot,
    shapes: pin.GeometryModel,
    link_of: Sequence[str],
    disabled: set[Pair],
    moving: set[int],
    samples: int,
    seed: int,
) -> SelfPairs:
    """Which link pairs of ``shapes`` to check, and why each other one is not: joined by a
    joint, ``disabled`` (an SRDF's), rigid (no ``moving`` joint between them), touching at
    home, or touching in nearly every one of ``samples`` random draws (``seed``)."""
    model, model_data = robot.model, robot.model.createData()
    joint_of = {link: g.parentJoint for link, g in zip(link_of, shapes.geometryObjects)}
    adjacent = adjacent_links(model, set(link_of))
    srdf, rigid, candidates = set(), set(), set()
    for pair in combinations(sorted(set(link_of)), 2):
        a, b = (joint_of[link] for link in pair)
        if pair in adjacent:
            continue
        if pair in disabled:
            srdf.add(pair)
        elif a == b or (a not in moving and b not in moving):
            rigid.add(pair)
        else:
            candidates.add(pair)
    home = [min(max(0.0, joint.lower), joint.upper) for joint in robot.joints]
    checks = build_checks(robot, shapes, link_of, [], candidates)
    at_home = hits(model, model_data, *checks, robot.configuration(home))
    always = _always_touching(robot, shapes, link_of, candidates - at_home, samples, seed)
    checked = candidates - at_home - always
    return SelfPairs(
        checked=frozenset(checked),
        adjacent=frozenset(adjacent),
        srdf=frozenset(srdf),
        rigid=frozenset(rigid),
        at_home=frozenset(at_home),
        always=frozenset(always),
        samples=samples,
    )


def _always_touching(
    robot: Robot,
    shapes: pin.GeometryModel,
    link_of: Sequence[str],
    candidates: set[Pair],
    samples: int,
    seed: int,
) -> set[Pair]:
    """The pairs touching in at least ``ALWAYS_FRACTION`` of ``samples`` random draws.

    A pair is dropped once it has missed too often to get there, and the
    draws stop when none is left: the answer is the one all the draws
    would give, usually after about ``(1 - ALWAYS_FRACTION) * samples``.
    """
    if samples <= 0:
        return set()
    allowed = samples - math.ceil(ALWAYS_FRACTION * samples)  # misses a pair may have
    misses: Counter[Pair] = Counter()
    active = set(candidates)
    model, model_data = robot.model, robot.model.createData()

    def build(pairs: set[Pair]) -> Checks:
        # the counts need no micrometres, and exact checks cost most on touching pairs
        return build_checks(robot, shapes, link_of, [], pairs, exact=False)

    checks = build(active)
    rng = np.random.default_rng(seed)
    for _ in range(samples):
        if not active:
            break
        found = hits(model, model_data, *checks, robot.configuration(robot.random(rng)))
        misses.update(active - found)
        dropped = {pair for pair in active if misses[pair] > allowed}
        if dropped:
            active -= dropped
            checks = build(active)
    return active


PART_PREFIX = "part/"
_OBJECT_PREFIX = "workcell/"

PartShape = tuple[str, Any, pin.SE3, "str | None", "frozenset[str]"]
"""A part for the checks: its name, coal shape, placement (in the model's root frame, or
with a link: in that link's frame, held by it) and the links it may touch."""


def add_parts(
    model: pin.Model,
    geometry: pin.GeometryModel,
    names: list[Any],
    link_of: Sequence[str],
    moving: Sequence[int],
    parts: Sequence[PartShape],
) -> None:
    """Add the parts to ``geometry`` and their pairs to it and to ``names`` (in place)."""
    robot_geoms = range(len(link_of))
    objects = [
        (k, obj.name[len(_OBJECT_PREFIX) :])
        for k, obj in enumerate(geometry.geometryObjects)
        if obj.name.startswith(_OBJECT_PREFIX)
    ]
    free: list[tuple[int, str]] = []
    for name, shape, placement, link, touch in parts:
        if link is not None:
            continue
        k = geometry.addGeometryObject(
            pin.GeometryObject(f"{PART_PREFIX}{name}", 0, 0, placement, shape)
        )
        free.append((k, name))
        for i in moving:
            if link_of[i] not in touch:
                geometry.addCollisionPair(pin.CollisionPair(i, k))
                names.append((link_of[i], name))
    for name, shape, placement, link, touch in parts:
        if link is None:
            continue
        frame_id = model.getFrameId(link)
        frame = model.frames[frame_id]
        k = geometry.addGeometryObject(
            pin.GeometryObject(
                f"{PART_PREFIX}{name}",
                frame.parentJoint,
                frame_id,
                frame.placement * placement,
                shape,
            )
        )
        for i in robot_geoms:
            fixed = geometry.geometryObjects[i].parentJoint == frame.parentJoint
            if not fixed and link_of[i] not in touch:
                geometry.addCollisionPair(pin.CollisionPair(i, k))
                names.append((link_of[i], name))
        for j, other in [*objects, *free]:
            geometry.addCollisionPair(pin.CollisionPair(k, j))
            names.append((name, other))


def held_as_links(
    geometry: pin.GeometryModel, moving: Sequence[int], link_of: Sequence[str]
) -> tuple[tuple[int, ...], tuple[str, ...]]:
    """The moving shapes with the held parts among them, and the name of every shape by
    geometry index (a held part's: its name), for a ``CheckGeometry``."""
    extra = [obj.name.split("/", 1)[-1] for obj in geometry.geometryObjects[len(link_of) :]]
    held = [
        k
        for k, obj in enumerate(geometry.geometryObjects)
        if k >= len(link_of) and obj.name.startswith(PART_PREFIX) and obj.parentJoint != 0
    ]
    return (*moving, *held), (*link_of, *extra)


def held_shapes(
    model: pin.Model, data: pin.Data, parts: Sequence[PartShape]
) -> list[tuple[str, Any, pin.SE3]]:
    """The held parts placed in the model's root frame (``data``'s joint placements)."""
    shapes = []
    for name, shape, placement, link, _ in parts:
        if link is None:
            continue
        frame = model.frames[model.getFrameId(link)]
        shapes.append((name, shape, data.oMi[frame.parentJoint] * frame.placement * placement))
    return shapes
