"""The meshes markers are drawn with: a sphere, a cube, a cylinder, an arrow (as RViz).

Made here with numpy, a few dozen triangles each, so that drawing markers needs no
mesh library (trimesh takes half a second to import, which the program's start should
not pay for a robot of boxes and cylinders). Every piece is convex and its triangles
face outwards. ``tests/view/test_marker_meshes.py`` holds them to trimesh's
``creation`` shapes of the same sizes.
"""

from __future__ import annotations

import functools

import numpy as np

__all__ = ["MARKER_SIZE_M", "Mesh", "marker_mesh"]

MARKER_SIZE_M = 0.03

Mesh = tuple[np.ndarray, np.ndarray]
"""Vertices [m], shape (v, 3), and triangles (indices into the vertices), shape (f, 3)."""


@functools.cache
def marker_mesh(shape: str, size: float = MARKER_SIZE_M) -> Mesh:
    """The mesh of one marker of ``shape`` (``protocol.MARKER_SHAPES``), centred; made once
    (the arrays are shared: do not change them).

    A sphere of diameter ``size``, a cube of edge ``size``, a cylinder of height ``size``
    along z, an arrow of length 1.7 ``size`` along x.
    """
    if shape == "cube":
        return _box(size)
    if shape == "cylinder":
        return _cylinder(size / 3, size, 24)
    if shape == "arrow":
        head = size / 2
        shaft_length = 1.7 * size - head
        shaft = _cylinder(size / 8, shaft_length, 16, z0=0.0)
        cone = _cone(size / 3, head, 16, z0=shaft_length)
        vertices, faces = _joined(shaft, cone)
        return vertices[:, [2, 1, 0]] * [1.0, 1.0, -1.0], faces  # along x: z -> x, x -> -z
    return _icosphere(size / 2, subdivisions=2)


def _outwards(vertices: np.ndarray, faces: np.ndarray) -> Mesh:
    """``faces`` wound so that each one's normal points away from the (convex) piece's
    centre."""
    centre = vertices.mean(axis=0)
    a, b, c = (vertices[faces[:, k]] for k in range(3))
    inward = np.einsum("ij,ij->i", np.cross(b - a, c - a), a - centre) < 0
    faces = faces.copy()
    faces[inward] = faces[inward][:, [0, 2, 1]]
    return vertices.astype(float), faces.astype(np.int64)


def _joined(*pieces: Mesh) -> Mesh:
    offsets = np.cumsum([0] + [len(v) for v, _ in pieces[:-1]])
    vertices = np.vstack([v for v, _ in pieces])
    faces = np.vstack([f + offset for (_, f), offset in zip(pieces, offsets, strict=True)])
    return vertices, faces


def _box(edge: float) -> Mesh:
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]) * edge / 2
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    faces = np.array([tri for a, b, c, d in quads for tri in ((a, b, c), (a, c, d))])
    return _outwards(corners, faces)


def _ring(radius: float, sections: int, z: float) -> np.ndarray:
    angles = np.linspace(0.0, 2 * np.pi, sections, endpoint=False)
    return np.column_stack([radius * np.cos(angles), radius * np.sin(angles), np.full(sections, z)])


def _cylinder(radius: float, height: float, sections: int, z0: float | None = None) -> Mesh:
    """Along z, from ``z0`` (default: centred on the origin) to ``z0 + height``."""
    low = -height / 2 if z0 is None else z0
    n = sections
    vertices = np.vstack(
        [_ring(radius, n, low), _ring(radius, n, low + height), [[0, 0, low], [0, 0, low + height]]]
    )
    k, nxt = np.arange(n), (np.arange(n) + 1) % n
    faces = np.vstack(
        [
            np.column_stack([k, nxt, n + nxt]),
            np.column_stack([k, n + nxt, n + k]),
            np.column_stack([np.full(n, 2 * n), nxt, k]),
            np.column_stack([np.full(n, 2 * n + 1), n + k, n + nxt]),
        ]
    )
    return _outwards(vertices, faces)


def _cone(radius: float, height: float, sections: int, z0: float) -> Mesh:
    """Its base at ``z0``, its tip at ``z0 + height``."""
    n = sections
    vertices = np.vstack([_ring(radius, n, z0), [[0, 0, z0 + height], [0, 0, z0]]])
    k, nxt = np.arange(n), (np.arange(n) + 1) % n
    faces = np.vstack(
        [np.column_stack([k, nxt, np.full(n, n)]), np.column_stack([np.full(n, n + 1), nxt, k])]
    )
    return _outwards(vertices, faces)


def _icosphere(radius: float, subdivisions: int) -> Mesh:
    t = (1.0 + 5**0.5) / 2
    corners = [
        *([-1, t, 0], [1, t, 0], [-1, -t, 0], [1, -t, 0]),
        *([0, -1, t], [0, 1, t], [0, -1, -t], [0, 1, -t]),
        *([t, 0, -1], [t, 0, 1], [-t, 0, -1], [-t, 0, 1]),
    ]
    vertices = [list(np.divide(c, np.linalg.norm(c))) for c in corners]
    faces = [
        *((0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11)),
        *((1, 5, 9), (5, 11, 4), (11, 10, 2), (10, 7, 6), (7, 1, 8)),
        *((3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9)),
        *((4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)),
    ]
    middle: dict[tuple[int, int], int] = {}  # an edge's midpoint (edges of every level)

    def mid(a: int, b: int) -> int:
        key = (min(a, b), max(a, b))
        if key not in middle:
            middle[key] = len(vertices)
            point = np.add(vertices[a], vertices[b]) / 2
            vertices.append(list(point / np.linalg.norm(point)))  # onto the sphere
        return middle[key]

    for _ in range(subdivisions):
        finer = []
        for a, b, c in faces:
            ab, bc, ca = mid(a, b), mid(b, c), mid(c, a)
            finer += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        faces = finer
    points = np.array(vertices, dtype=float)
    points *= radius / np.linalg.norm(points, axis=1, keepdims=True)
    return _outwards(points, np.array(faces))
