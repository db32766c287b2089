"""The robot's collision geometry, what its structure says about link pairs, and the
geometry of parts.

``robot_geometry`` builds Pinocchio's ``GeometryModel`` of the robot's full model
(so mimic and off-chain links are in it) from each link's URDF ``<collision>``
elements, or its ``<visual>`` ones where it has none. Meshes are resolved like
the viewer's, through ``RobotSource``, and replaced by their convex hulls so a
check stays a few microseconds. ``adjacent_links``, ``moving_joints`` and the
SRDF reader give the pairs never worth checking; ``checks.choose_pairs`` samples the rest.

The parts' geometry (``signed_distance``, ``extent``, ``contains``, ``drop``): how far
apart two shapes are, how wide a part is along a line, and how far a released part drops
straight down before it meets something.

Shapes are coal geometries placed by ``pin.SE3`` placements in one frame (the world's).
Sizes follow the workcell's: a box's (x, y, z) edges, a cylinder's (radius, length) along
its own z axis, a sphere's (radius,), centred on the placement [m].
"""

from __future__ import annotations

import copy
import math
import warnings
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from dataclasses import dataclass
from itertools import combinations
from pathlib import Path

import coal
import numpy as np
import pinocchio as pin

from ..errors import C2rvizError
from ..robot.model import Robot
from ..robot.sources import MissingMesh, RobotSource

Pair = tuple[str, str]


class CollisionError(C2rvizError):
    """Root of the collision errors."""


class CollisionModelError(CollisionError):
    """The robot's collision geometry cannot be built."""


class SrdfError(CollisionError):
    """An SRDF file that cannot be read or has a malformed entry."""


@dataclass(frozen=True)
class SelfPairs:
    """How each pair of the robot's links with geometry is treated.

    Every pair ``(a, b)`` with ``a < b`` is in exactly one set, tested in this
    order: ``adjacent`` (joined by a joint), ``srdf`` (disabled there),
    ``rigid`` (never move relative to each other), ``at_home`` (touching at
    home), ``always`` (touching in at least ``ALWAYS_FRACTION`` of ``samples``
    random configurations); the rest are ``checked``.
    """

    checked: frozenset[Pair]
    adjacent: frozenset[Pair]
    srdf: frozenset[Pair]
    rigid: frozenset[Pair]
    at_home: frozenset[Pair]
    always: frozenset[Pair]
    samples: int


def ordered_pair(a: str, b: str) -> Pair:
    return (a, b) if a <= b else (b, a)


def coal_message(exc: BaseException) -> str:
    """The part of a coal or Pinocchio exception a user can act on, on one line."""
    text = str(exc)
    return " ".join(text.split("message:", 1)[-1].split()) or type(exc).__name__


def parse_srdf(text: str, where: str = "SRDF") -> list[Pair]:
    """The ``<disable_collisions link1= link2=/>`` pairs of an SRDF text.

    Raises:
        SrdfError: not XML, or an entry without both links.
    """
    try:
        root = ET.fromstring(text)
    except ET.ParseError as exc:
        raise SrdfError(f"{where} is not valid XML: {exc}") from exc
    pairs = []
    for entry in root.iter("disable_collisions"):
        a, b = entry.get("link1"), entry.get("link2")
        if not a or not b:
            raise SrdfError(f"{where}: a <disable_collisions> entry lacks link1 or link2")
        pairs.append(ordered_pair(a, b))
    return pairs


def read_srdf(path: str | Path) -> list[Pair]:
    """``parse_srdf`` of the file at ``path`` (raises ``SrdfError``)."""
    try:
        text = Path(path).read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise SrdfError(f"cannot read SRDF {path}: {exc}") from exc
    return parse_srdf(text, str(path))


def collision_xml(source: RobotSource) -> tuple[str, list[str]]:
    """The URDF as Pinocchio should read it for collisions, and what was dropped.

    A link without ``<collision>`` gets copies of its ``<visual>`` geometry;
    every mesh becomes the absolute path ``source.resolve`` finds, and an element
    whose mesh is nowhere is dropped with a warning (returned).

    Raises:
        CollisionModelError: the URDF text is not XML ElementTree can read.
    """
    try:
        root = ET.fromstring(source.xml)
    except ET.ParseError as exc:
        raise CollisionModelError(f"cannot read the URDF for collision geometry: {exc}") from exc
    notes = []
    for link in root.findall("link"):
        if link.find("collision") is None:
            for visual in link.findall("visual"):
                element = ET.SubElement(link, "collision")
                for child in visual:
                    if child.tag in ("origin", "geometry"):
                        element.append(copy.deepcopy(child))
        for element in link.findall("collision"):
            mesh = element.find("geometry/mesh")
            if mesh is None:
                continue
            uri = mesh.get("filename", "")
            path = source.resolve(uri)
            if path is None:
                link.remove(element)
                missing = MissingMesh(uri, (link.get("name", "?"),), tuple(source.searched(uri)))
                notes.append(missing.message() + " (no collision geometry from it)")
            else:
                mesh.set("filename", str(path))
    return ET.tostring(root, encoding="unicode"), notes


def moving_joints(robot: Robot) -> set[int]:
    """Joints the chain moves: chain joints, mimic joints, and all below them."""
    model = robot.model
    roots = {model.getJointId(joint.name) for joint in robot.joints}
    roots |= {j for j in range(1, model.njoints) if model.joints[j].nq == 0}  # mimic
    moving: set[int] = set()
    for j in range(1, model.njoints):  # a parent comes before its children
        if j in roots or model.parents[j] in moving:
            moving.add(j)
    return moving


def adjacent_links(model: pin.Model, has_geometry: set[str]) -> set[Pair]:
    """Links joined by a joint; a link without geometry joins all its neighbours."""
    frames = model.frames
    parent: dict[str, str | None] = {}
    for frame in frames:
        if frame.type == pin.FrameType.BODY:
            # a link hangs from a joint frame, which hangs from the parent link
            over = frames[frames[frame.parentFrame].parentFrame]
            parent[frame.name] = over.name if over.type == pin.FrameType.BODY else None
    children: dict[str, list[str]] = {name: [] for name in parent}
    for name, up in parent.items():
        if up is not None:
            children[up].append(name)

    def below(link: str) -> list[str]:  # nearest links with geometry under ``link``
        found = []
        for child in children[link]:
            found.extend([child] if child in has_geometry else below(child))
        return found

    def above(link: str) -> list[str]:  # nearest link with geometry over ``link``
        up = parent[link]
        while up is not None and up not in has_geometry:
            up = parent[up]
        return [] if up is None else [up]

    adjacent: set[Pair] = set()
    for link in parent:
        if link in has_geometry:
            adjacent.update(ordered_pair(link, child) for child in below(link))
        else:
            group = below(link) + above(link)
            adjacent.update(ordered_pair(a, b) for a, b in combinations(group, 2))
    return adjacent


def _make_convex(geometry: pin.GeometryModel) -> list[str]:
    """Replace each mesh by its convex hull (GJK on a hull is far quicker than a BVH)."""
    notes = []
    for obj in geometry.geometryObjects:
        shape = obj.geometry
        if isinstance(shape, coal.BVHModelBase):
            try:
                shape.buildConvexRepresentation(False)
                obj.geometry = shape.convex
            except Exception as exc:  # qhull refuses flat or degenerate meshes
                notes.append(
                    f"collision mesh {obj.meshPath} kept as triangles: {coal_message(exc)}"
                )
    return notes


def robot_geometry(robot: Robot, convex: bool = True) -> tuple[pin.GeometryModel, list[str]]:
    """The robot's collision geometry on its full model, and what was dropped or kept.

    Args:
        robot: The robot (its ``source`` resolves the meshes).
        convex: Replace meshes by their convex hulls (quicker, a little larger).

    Raises:
        CollisionModelError: Pinocchio cannot build it (a mesh it cannot read).
    """
    xml, notes = collision_xml(robot.source)
    try:
        geometry = pin.buildGeomFromUrdfString(
            robot.model, xml, pin.GeometryType.COLLISION, package_dirs=[]
        )
    except (RuntimeError, ValueError) as exc:
        raise CollisionModelError(
            f"cannot build the collision geometry of {robot.name}: {coal_message(exc)}"
        ) from exc
    if convex:
        notes += _make_convex(geometry)
    return geometry, notes


def configure_requests(data: pin.GeometryData, exact: bool = True) -> None:
    """Make every collision request of ``data`` free of history, and exact if asked.

    With coal 3.0's defaults as Pinocchio sets them, a boolean check (no
    contact) lets GJK stop early and warm-starts it from the previous query:
    that missed contacts up to 3 cm deep between two cylinders and made the
    answer depend on the configuration checked before. Dropping the warm start
    makes the answer a function of the configuration alone (still missing
    contacts ~1 mm deep); asking for the contact (``exact``) runs GJK to its
    end, and EPA on a hit, which costs more only where shapes touch.
    """
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)  # the warm start's old switch
        for request in data.collisionRequests:
            request.enable_contact = exact
            request.enable_cached_gjk_guess = False


Obstacle = tuple[str, coal.CollisionGeometry, pin.SE3]
"""Something a part may rest on: its name, its shape, its placement in the world."""

_MIN_STEP_M = 0.0005  # a falling part moves down at least this much between two checks
_TOUCH_M = 1e-5  # closer than this is touching


def _transform(placement: pin.SE3) -> coal.Transform3s:
    return coal.Transform3s(placement.rotation, placement.translation)


def signed_distance(
    a: coal.CollisionGeometry, pa: pin.SE3, b: coal.CollisionGeometry, pb: pin.SE3
) -> float:
    """The distance between two placed shapes [m]; negative: how deep they overlap."""
    result = coal.DistanceResult()
    request = coal.DistanceRequest()
    return float(coal.distance(a, _transform(pa), b, _transform(pb), request, result))


def extent(shape: str, size: Sequence[float], rotation: np.ndarray, direction: np.ndarray) -> float:
    """How far the shape reaches from its centre along the unit ``direction`` [m] (half its
    width across that direction), its axes turned by ``rotation``."""
    local = rotation.T @ np.asarray(direction, dtype=float)
    if shape == "box":
        return float(sum(abs(local[i]) * size[i] / 2.0 for i in range(3)))
    if shape == "cylinder":
        radius, length = size
        along = abs(float(local[2]))
        return radius * math.sqrt(max(0.0, 1.0 - along * along)) + length / 2.0 * along
    return float(size[0])


def contains(shape: str, size: Sequence[float], placement: pin.SE3, point: np.ndarray) -> bool:
    """True when ``point`` (same frame as ``placement``) lies inside the shape."""
    local = placement.actInv(np.asarray(point, dtype=float))
    if shape == "box":
        return all(abs(local[i]) <= size[i] / 2.0 + 1e-9 for i in range(3))
    if shape == "cylinder":
        radius, length = size
        return math.hypot(local[0], local[1]) <= radius + 1e-9 and abs(local[2]) <= length / 2.0
    return float(np.linalg.norm(local)) <= size[0] + 1e-9


def drop(
    shape: str,
    size: Sequence[float],
    geometry: coal.CollisionGeometry,
    placement: pin.SE3,
    obstacles: Sequence[Obstacle],
    floor: str = "floor",
) -> tuple[float, str]:
    """How far the part drops straight down before it touches something, and what [m].

    The floor is the plane z = 0. Obstacles the part already overlaps at the start are
    passed by (it was put there). Conservative advancement: the part moves down by its
    distance to the nearest obstacle (at least ``_MIN_STEP_M``), and a step that would
    overlap is halved until it touches.
    """
    bottom = float(placement.translation[2]) - extent(
        shape, size, placement.rotation, np.array([0.0, 0.0, -1.0])
    )
    to_floor = max(bottom, 0.0)
    start = [
        (name, shape_b, where)
        for name, shape_b, where in obstacles
        if signed_distance(geometry, placement, shape_b, where) > -_TOUCH_M
    ]

    def nearest(down: float) -> tuple[float, str]:
        lowered = pin.SE3(placement.rotation, placement.translation - np.array([0, 0, down]))
        best, what = to_floor - down, floor
        for name, shape_b, where in start:
            distance = signed_distance(geometry, lowered, shape_b, where)
            if distance < best:
                best, what = distance, name
        return best, what

    down = 0.0
    gap, what = nearest(down)
    for _ in range(100_000):
        if gap <= _TOUCH_M:
            break
        step = max(gap, _MIN_STEP_M)
        if down + step > to_floor:
            step = to_floor - down
        new_gap, new_what = nearest(down + step)
        while new_gap < -_TOUCH_M and step > _TOUCH_M:  # overlapped: halve the step
            step /= 2.0
            new_gap, new_what = nearest(down + step)
        down += step
        gap, what = new_gap, new_what
        if down >= to_floor:
            return to_floor, floor
    return down, what
