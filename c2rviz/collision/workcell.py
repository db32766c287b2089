"""The workcell: fixed objects around the robot, placed in its base frame.

An object is a box, sphere, cylinder or mesh with a name, a size, a placement in
the robot's base frame and a colour for drawing. ``Workcell`` holds them in the
order they were first set and checks every input; ``collision_geometry`` turns
one into coal's shape. Nothing here knows the robot's joints: ``checks.build_checks``
puts the shapes next to the links.

Sizes follow the URDF: a box is (x, y, z) edge lengths, a sphere (radius,), a
cylinder (radius, length) with its length along its own z axis, all centred on
the placement, in metres. A mesh's size is its scale factors (x, y, z); mesh
files come from the configuration only (the caller decides who may name files).
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path

import coal
import numpy as np
import pinocchio as pin

from ..errors import C2rvizError, shown
from .geometry import coal_message

SHAPES = ("box", "cylinder", "mesh", "sphere")
SIZE_NAMES: dict[str, tuple[str, ...]] = {
    "box": ("x", "y", "z"),
    "cylinder": ("radius", "length"),
    "mesh": ("scale_x", "scale_y", "scale_z"),
    "sphere": ("radius",),
}
DEFAULT_RGBA = (0.55, 0.62, 0.75, 0.5)  # translucent grey-blue
MAX_OBJECTS = 100
MAX_NAME_LENGTH = 64
_NAME = re.compile(r"[A-Za-z0-9_.-]+")
_RESERVED = ("all",)


class WorkcellError(C2rvizError):
    """A workcell object that cannot be set (bad name, shape, size, colour, file)."""


class BadObjectName(WorkcellError):
    """A name that is not a plain word, is reserved, or names a robot link."""

    def __init__(self, name: str, problem: str) -> None:
        self.name = name
        super().__init__(f"object name {shown(name)} {problem}")


class BadShape(WorkcellError):
    """A shape that is not one of ``SHAPES``."""

    def __init__(self, shape: str) -> None:
        self.shape = shape
        super().__init__(f"unknown shape {shown(shape)} (choose from: {', '.join(SHAPES)})")


class BadSize(WorkcellError):
    """Sizes of the wrong count, or not positive and finite."""

    def __init__(self, shape: str, size: Sequence[float], problem: str) -> None:
        self.shape = shape
        self.size = tuple(size)
        names = ",".join(SIZE_NAMES[shape])
        super().__init__(f"{shape} size {problem} (a {shape} takes {names}, each > 0 and finite)")


class BadColour(WorkcellError):
    """A colour that is not 3 or 4 values in 0..1."""

    def __init__(self, rgba: Sequence[float]) -> None:
        self.rgba = tuple(rgba)
        values = ",".join(f"{v:.4g}" for v in self.rgba)
        super().__init__(f"colour {values} is not r,g,b or r,g,b,a with each value in 0..1")


class BadPlacement(WorkcellError):
    """A placement with a non-finite entry."""

    def __init__(self, name: str) -> None:
        self.name = name
        super().__init__(f"placement of object {name!r} has a non-finite entry")


class BadMesh(WorkcellError):
    """A mesh file that does not exist or cannot be read."""

    def __init__(self, path: Path | str | None, problem: str) -> None:
        self.path = path
        super().__init__(f"mesh {path}: {problem}")


class TooManyObjects(WorkcellError):
    """A new object past the workcell's limit."""

    def __init__(self, limit: int) -> None:
        self.limit = limit
        super().__init__(f"the workcell already holds {limit} objects, its limit; remove one first")


class UnknownObject(WorkcellError):
    """A name that is not in the workcell."""

    def __init__(self, name: str, names: Sequence[str]) -> None:
        self.name = name
        self.names = tuple(names)
        have = ", ".join(self.names) if self.names else "none"
        super().__init__(f"no object named {shown(name)} (objects: {have})")


@dataclass(frozen=True, eq=False)
class WorkcellObject:
    """One fixed object of the workcell.

    Attributes:
        name: ASCII word (``[A-Za-z0-9_.-]+``), unique in the workcell.
        shape: One of ``SHAPES``.
        size: Box (x, y, z) [m]; sphere (radius,) [m]; cylinder (radius,
            length) [m]; mesh (scale_x, scale_y, scale_z).
        placement: Pose of the shape's centre (a mesh's origin) in the robot's
            base frame; a private copy, do not modify it.
        rgba: Colour for drawing, each channel 0..1.
        mesh_path: The mesh file (shape ``mesh`` only).
    """

    name: str
    shape: str
    size: tuple[float, ...]
    placement: pin.SE3
    rgba: tuple[float, float, float, float] = DEFAULT_RGBA
    mesh_path: Path | None = None


def _check_name(name: str, reserved: Iterable[str]) -> None:
    if not isinstance(name, str) or not _NAME.fullmatch(name):
        raise BadObjectName(
            str(name), "is not a word of letters, digits, '_', '.' or '-' (no spaces or '/')"
        )
    if len(name) > MAX_NAME_LENGTH:
        raise BadObjectName(name, f"is longer than {MAX_NAME_LENGTH} characters")
    if name.lower() in _RESERVED:
        raise BadObjectName(name, "is reserved (it means every object)")
    if name in reserved:
        raise BadObjectName(name, "is a link of the robot; choose another name")


def _check_size(shape: str, size: Sequence[float]) -> tuple[float, ...]:
    try:
        values = tuple(float(v) for v in size)
    except (TypeError, ValueError):
        raise BadSize(shape, (), f"{shown(str(size))} is not a list of numbers") from None
    if shape == "mesh" and len(values) in (0, 1):
        values = (values[0],) * 3 if values else (1.0, 1.0, 1.0)  # no scale, or uniform
    needed = len(SIZE_NAMES[shape])
    if len(values) != needed:
        raise BadSize(shape, values, f"needs {needed} values, got {len(values)}")
    for value in values:
        if not (math.isfinite(value) and value > 0.0):
            raise BadSize(shape, values, f"value {value:.6g} is not > 0 and finite")
    return values


def _check_rgba(rgba: Sequence[float] | None) -> tuple[float, float, float, float]:
    if rgba is None:
        return DEFAULT_RGBA
    try:
        values = tuple(float(v) for v in rgba)
    except (TypeError, ValueError):
        raise BadColour(()) from None
    if len(values) not in (3, 4) or not all(0.0 <= v <= 1.0 for v in values):
        raise BadColour(values)
    r, g, b, *alpha = values
    return (r, g, b, alpha[0] if alpha else 1.0)


def make_object(
    name: str,
    shape: str,
    size: Sequence[float],
    placement: pin.SE3,
    rgba: Sequence[float] | None = None,
    mesh_path: str | Path | None = None,
    reserved: Iterable[str] = (),
) -> WorkcellObject:
    """A checked ``WorkcellObject`` (see ``Workcell.set``)."""
    _check_name(name, reserved)
    if shape not in SHAPES:
        raise BadShape(str(shape))
    values = _check_size(shape, size)
    colour = _check_rgba(rgba)
    if not np.isfinite(placement.homogeneous).all():
        raise BadPlacement(name)
    path = None
    if shape == "mesh":
        if mesh_path is None:
            raise BadMesh(None, f"object {name!r} is a mesh but no file was given")
        path = Path(mesh_path).expanduser().resolve()
        if not path.is_file():
            raise BadMesh(path, "no such file")
    elif mesh_path is not None:
        raise BadMesh(mesh_path, f"only a mesh takes a file, not a {shape}")
    return WorkcellObject(name, shape, values, pin.SE3(placement), colour, path)


def collision_geometry(obj: WorkcellObject) -> coal.CollisionGeometry:
    """Coal's shape for ``obj`` (a mesh is read from its file, kept exact, not convex).

    Raises:
        BadMesh: the mesh file cannot be read.
    """
    if obj.shape == "box":
        return coal.Box(*obj.size)
    if obj.shape == "sphere":
        return coal.Sphere(obj.size[0])
    if obj.shape == "cylinder":
        return coal.Cylinder(obj.size[0], obj.size[1])
    try:
        mesh = coal.MeshLoader().load(str(obj.mesh_path), np.array(obj.size))
    except Exception as exc:  # assimp raises whatever it meets
        raise BadMesh(obj.mesh_path, f"cannot be read: {coal_message(exc)}") from exc
    if mesh.num_tris == 0:
        raise BadMesh(obj.mesh_path, "holds no triangles")
    return mesh


class Workcell:
    """The objects, in the order they were first set, with their coal shapes."""

    def __init__(self, reserved: Iterable[str] = (), max_objects: int = MAX_OBJECTS) -> None:
        """An empty workcell.

        Args:
            reserved: Names objects may not take (the robot's links).
            max_objects: Most objects held at once.
        """
        self.reserved = frozenset(reserved)
        self.max_objects = max_objects
        self._objects: dict[str, tuple[WorkcellObject, coal.CollisionGeometry]] = {}

    def set(
        self,
        name: str,
        shape: str,
        size: Sequence[float],
        placement: pin.SE3,
        rgba: Sequence[float] | None = None,
        mesh_path: str | Path | None = None,
    ) -> WorkcellObject:
        """Add the object, or replace the one of that name (keeping its place).

        Raises:
            WorkcellError: a bad name, shape, size, colour, placement or mesh
                file, or a new object past ``max_objects``; nothing changes.
        """
        obj = make_object(name, shape, size, placement, rgba, mesh_path, self.reserved)
        if name not in self._objects and len(self._objects) >= self.max_objects:
            raise TooManyObjects(self.max_objects)
        self._objects[name] = (obj, collision_geometry(obj))
        return obj

    def remove(self, name: str) -> None:
        """Remove one object.

        Raises:
            UnknownObject: there is no object of that name.
        """
        if name not in self._objects:
            raise UnknownObject(name, self.names())
        del self._objects[name]

    def clear(self) -> None:
        """Remove every object."""
        self._objects.clear()

    def names(self) -> list[str]:
        """The objects' names, in the order they were first set."""
        return list(self._objects)

    def get(self, name: str) -> WorkcellObject:
        """The object called ``name`` (raises ``UnknownObject``)."""
        if name not in self._objects:
            raise UnknownObject(name, self.names())
        return self._objects[name][0]

    def items(self) -> list[tuple[WorkcellObject, coal.CollisionGeometry]]:
        """Every object with its coal shape, in order."""
        return list(self._objects.values())

    def __len__(self) -> int:
        return len(self._objects)

    def __contains__(self, name: object) -> bool:
        return name in self._objects
