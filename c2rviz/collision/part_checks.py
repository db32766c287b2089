"""Parts in a robot's collision checks, as MoveIt checks its attached objects.

A part no robot holds is an obstacle, placed in the model's root frame, checked against
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

from collections.abc import Sequence
from typing import Any

import pinocchio as pin

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
