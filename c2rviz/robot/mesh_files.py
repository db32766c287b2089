"""STL, OBJ and COLLADA mesh files read with numpy (trimesh takes half a second to import).

A robot's page is built at the program's start, so reading its mesh files must not
pay for a mesh library: ``read_mesh`` reads the formats robot descriptions use most,
STL (binary or ASCII), Wavefront OBJ (its ``.mtl`` diffuse colours, one piece per
material) and COLLADA ``.dae`` (``collada``: one piece per primitive and placement, in
its material's diffuse colour), into ``Mesh`` pieces; ``visuals`` hands any other
format (``.ply``, glTF ...), and a file these readers refuse (a texture, say), to
trimesh, imported then. As trimesh does,
an STL's corners shared by several triangles become one vertex (so the page shades
it smooth), and an OBJ keeps its own vertices. ``tests/robot/test_mesh_files.py``
holds both to trimesh's reading of the same files.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

import numpy as np

from .collada import read_collada
from .mesh import Mesh, MeshFileError

__all__ = ["FORMATS", "Mesh", "MeshFileError", "merged", "read_mesh"]

FORMATS = (".stl", ".obj", ".dae")
"""The suffixes read here (any case); others go to trimesh."""
_MAX_BYTES = 512 * 1024 * 1024  # a mesh file this big is refused (trimesh is asked)


def read_mesh(path: Path) -> list[Mesh]:
    """The pieces of the STL or OBJ file at ``path`` (one, or one per OBJ material).

    Raises:
        MeshFileError: the file is not one this reader understands.
        OSError: it cannot be read.
    """
    suffix = path.suffix.lower()
    if suffix not in FORMATS:
        raise MeshFileError(f"{path.name}: not {' or '.join(FORMATS)}")
    if os.path.getsize(path) > _MAX_BYTES:
        raise MeshFileError(f"{path.name}: larger than {_MAX_BYTES} bytes")
    data = path.read_bytes()
    if suffix == ".dae":
        pieces = read_collada(data)
    else:
        pieces = _stl(data) if suffix == ".stl" else _obj(data, path.parent)
    pieces = [p for p in pieces if len(p.faces)]
    if not pieces:
        raise MeshFileError(f"{path.name}: no triangles")
    return pieces


def _stl(data: bytes) -> list[Mesh]:
    if len(data) >= 84:
        count = int.from_bytes(data[80:84], "little")
        if 84 + 50 * count == len(data):  # binary: 50 bytes a triangle
            record = np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")])
            corners = np.frombuffer(data, record, count, 84)["v"].reshape(-1, 3)
            return [merged(corners.astype(float))]
    if not data.lstrip()[:5].lower() == b"solid":
        raise MeshFileError("neither a binary STL nor an ASCII one")
    numbers = re.findall(rb"^\s*vertex\s+(\S+)\s+(\S+)\s+(\S+)", data, re.MULTILINE)
    if not numbers or len(numbers) % 3:
        raise MeshFileError("an ASCII STL whose facets are not triangles")
    return [merged(np.array(numbers, dtype=float))]


def merged(corners: np.ndarray) -> Mesh:
    """Triangles given corner by corner (3k, 3), each distinct corner one vertex."""
    if not np.all(np.isfinite(corners)):
        raise MeshFileError("a corner is not a finite number")
    vertices, index = np.unique(corners, axis=0, return_inverse=True)
    return Mesh(vertices, index.reshape(-1, 3).astype(np.int64))


def _obj(data: bytes, folder: Path) -> list[Mesh]:
    vertices: list[list[float]] = []
    faces: dict[str | None, list[list[int]]] = {}
    material: str | None = None
    colours: dict[str, tuple[float, float, float, float]] = {}
    for raw in data.splitlines():
        words = raw.split(b"#", 1)[0].split()
        if not words:
            continue
        key = words[0]
        if key == b"v":
            vertices.append([float(w) for w in words[1:4]])
        elif key == b"f":
            k = len(vertices)
            corners = [_obj_index(w, k) for w in words[1:]]
            fan = range(1, len(corners) - 1)  # a polygon: a fan of triangles from its first
            faces.setdefault(material, []).extend(
                [corners[0], corners[i], corners[i + 1]] for i in fan
            )
        elif key == b"usemtl":
            material = words[1].decode("utf-8", "replace") if len(words) > 1 else None
        elif key == b"mtllib":
            for lib in words[1:]:
                colours.update(_mtl(folder / lib.decode("utf-8", "replace")))
    points = np.array(vertices, dtype=float).reshape(-1, 3)
    if not np.all(np.isfinite(points)):
        raise MeshFileError("a vertex is not a finite number")
    pieces = []
    for name, triangles in faces.items():
        index = np.array(triangles, dtype=np.int64).reshape(-1, 3)
        if len(index) and (index.min() < 0 or index.max() >= len(points)):
            raise MeshFileError("a face names a vertex that is not there")
        used, local = np.unique(index, return_inverse=True)
        colour = colours.get(name) if name is not None else None
        pieces.append(Mesh(points[used], local.reshape(-1, 3), colour))
    return pieces


def _obj_index(word: bytes, count: int) -> int:
    """A face corner's vertex index (``v``, ``v/vt``, ``v//vn``, ``v/vt/vn``; 1-based, or
    negative from the end), 0-based."""
    index = int(word.split(b"/", 1)[0])
    return index - 1 if index > 0 else count + index


def _mtl(path: Path) -> dict[str, tuple[float, float, float, float]]:
    """Each material's diffuse colour (``Kd``) and opacity (``d``) in a ``.mtl`` file."""
    try:
        text = path.read_bytes()
    except OSError:
        return {}
    out: dict[str, tuple[float, float, float, float]] = {}
    name: str | None = None
    rgb, alpha = (1.0, 1.0, 1.0), 1.0
    for raw in [*text.splitlines(), b"newmtl"]:  # the last one ends at the end
        words = raw.split(b"#", 1)[0].split()
        if not words:
            continue
        if words[0] == b"newmtl":
            if name is not None:
                out[name] = (*rgb, alpha)
            name = words[1].decode("utf-8", "replace") if len(words) > 1 else None
            rgb, alpha = (1.0, 1.0, 1.0), 1.0
        elif words[0] == b"Kd" and len(words) >= 4:
            r, g, b = (min(max(float(w), 0.0), 1.0) for w in words[1:4])
            rgb = (r, g, b)
        elif words[0] == b"d" and len(words) >= 2:
            alpha = min(max(float(words[1]), 0.0), 1.0)
    return out
