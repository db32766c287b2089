"""The geometry models that do the checking, and which of a robot's link pairs they check.

``build_checks`` makes a coal geometry model of the robot's shapes that checks the given
link pairs, the workcell objects against every moving link, and the parts
(``part_checks.add_parts``); ``hits`` says which of its pairs collide at a
configuration. ``choose_pairs`` settles, once per robot, which link pairs are worth
checking, as MoveIt's setup assistant does (``model.py`` says how).
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Sequence
from itertools import combinations

import coal
import numpy as np
import pinocchio as pin

from ..robot.model import Robot
from .geometry import Pair, SelfPairs, adjacent_links, configure_requests, ordered_pair
from .part_checks import PartShape, add_parts
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
    ``moving_geoms`` (and ``parts``: see ``part_checks.add_parts``); ``exact``: distances
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
