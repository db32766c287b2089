"""Markers in the page: one batched node per robot and shape, rebuilt once per frame, and
the meshes they are drawn with.

A marker costs O(1) where the command runs: ``add`` writes it into its
robot's ring of ``MAX_MARKERS`` slots (the oldest is overwritten), and
``clear`` forgets them all. Once per frame the send calls ``draw``, which
hands each changed robot's markers, shape by shape, to one viser batched-mesh
node (``/markers/<robot>/<shape>``) as new instance arrays. The node's state
is replaced, never removed and added again, so viser's buffer holds one
update per node whatever the number of markers sent.

The meshes (``marker_mesh``): a sphere, a cube, a cylinder, an arrow (as RViz), made here
with numpy, a few dozen triangles each, so that drawing markers needs no mesh library
(trimesh takes half a second to import, which the program's start should not pay for a
robot of boxes and cylinders). Every piece is convex and its triangles
face outwards. ``tests/view/test_marker_meshes.py`` holds them to trimesh's
``creation`` shapes of the same sizes.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Iterable
from typing import Any

import numpy as np
import viser

from ..protocol.grammar import MARKER_SHAPES
from ..world.observer import MAX_MARKERS
from ..world.state import Marker
from . import adapter
from .robot_view import node_name


class _Ring:
    """One robot's newest ``MAX_MARKERS`` markers, as arrays (slot order, not age)."""

    def __init__(self) -> None:
        self.positions = np.zeros((MAX_MARKERS, 3), dtype=np.float32)
        self.wxyzs = np.zeros((MAX_MARKERS, 4), dtype=np.float32)
        self.colors = np.zeros((MAX_MARKERS, 3), dtype=np.uint8)
        self.shapes = np.zeros(MAX_MARKERS, dtype=np.int8)
        self.markers: list[Marker | None] = [None] * MAX_MARKERS
        self.count = 0
        self.next = 0
        self.dirty = False


class MarkerLayer:
    """Every robot's markers, drawn as batched meshes; see the module docstring.

    Attributes:
        nodes: The batched-mesh node of each (robot, shape) drawn so far.
    """

    def __init__(
        self,
        server: viser.ViserServer,
        segments: dict[str, str],
        pick: Callable[[str, str, int], None] | None = None,
    ) -> None:
        """Draw in ``server``'s scene; ``segments`` names each robot's node segment.

        ``pick(robot, shape, instance)`` is told of a click on a marker, on
        viser's thread (``marker_at`` finds it, on the asyncio thread).
        """
        self._server = server
        self._scene = server.scene
        self._segments = segments
        self._pick = pick
        self._instances: dict[tuple[str, str], np.ndarray] = {}  # slot of each drawn instance
        self._rings: dict[str, _Ring] = {}
        self._shape_index = {shape: k for k, shape in enumerate(MARKER_SHAPES)}
        self.nodes: dict[tuple[str, str], Any] = {}
        self.dirty = False

    def add(self, robot: str, marker: Marker) -> None:
        """One more marker of ``robot`` (past ``MAX_MARKERS`` its oldest goes)."""
        ring = self._rings.get(robot)
        if ring is None:
            ring = self._rings[robot] = _Ring()
        slot = ring.next
        ring.positions[slot] = marker.position
        ring.wxyzs[slot] = marker.wxyz
        ring.colors[slot] = [round(c * 255.0) for c in marker.rgb]
        ring.shapes[slot] = self._shape_index.get(marker.shape, 0)
        ring.markers[slot] = marker
        ring.next = (slot + 1) % MAX_MARKERS
        ring.count = min(ring.count + 1, MAX_MARKERS)
        ring.dirty = self.dirty = True

    def clear(self, robot: str) -> None:
        """Every marker of ``robot`` is gone."""
        ring = self._rings.get(robot)
        if ring is not None and ring.count:
            ring.count = ring.next = 0
            ring.markers = [None] * MAX_MARKERS
            ring.dirty = self.dirty = True

    def count(self, robot: str | None = None) -> int:
        """Markers held for ``robot`` (None: for every robot)."""
        rings = self._rings.values() if robot is None else [self._rings.get(robot)]
        return sum(ring.count for ring in rings if ring is not None)

    def marker_at(self, robot: str, shape: str, instance: int) -> Marker | None:
        """The marker drawn as ``instance`` of ``robot``'s ``shape`` node, if it is still held."""
        slots = self._instances.get((robot, shape))
        ring = self._rings.get(robot)
        if slots is None or ring is None or not 0 <= instance < len(slots):
            return None
        return ring.markers[int(slots[instance])]

    def draw(self) -> None:
        """Hand each changed robot's markers to its nodes (once per frame, in a send)."""
        if not self.dirty:
            return
        self.dirty = False
        for robot, ring in self._rings.items():
            if not ring.dirty:
                continue
            ring.dirty = False
            shapes = ring.shapes[: ring.count]
            for shape, k in self._shape_index.items():
                chosen = np.flatnonzero(shapes == k)
                self._show(robot, shape, ring, chosen)

    def draw_these(self, robot: str, markers: Iterable[Marker]) -> None:
        """Draw ``markers`` as ``robot``'s instead of those it holds (the page looking back);
        a click on them picks nothing. ``redraw`` shows the held ones again."""
        ring = _Ring()
        for k, marker in enumerate(markers):
            ring.positions[k] = marker.position
            ring.wxyzs[k] = marker.wxyz
            ring.colors[k] = [round(c * 255.0) for c in marker.rgb]
            ring.shapes[k] = self._shape_index.get(marker.shape, 0)
            ring.count = k + 1
        shapes = ring.shapes[: ring.count]
        for shape, k in self._shape_index.items():
            self._show(robot, shape, ring, np.flatnonzero(shapes == k))
            self._instances.pop((robot, shape), None)

    def redraw(self) -> None:
        """Draw every robot's held markers again at the next ``draw``."""
        for robot, _ in self.nodes:
            self._rings.setdefault(robot, _Ring())
        for ring in self._rings.values():
            ring.dirty = True
        self.dirty = True

    def _show(self, robot: str, shape: str, ring: _Ring, chosen: np.ndarray) -> None:
        node = self.nodes.get((robot, shape))
        if node is None and not len(chosen):
            return
        positions = ring.positions[chosen]
        wxyzs = ring.wxyzs[chosen]
        colors = ring.colors[chosen]
        self._instances[robot, shape] = chosen
        if node is None:
            vertices, faces = marker_mesh(shape)
            self.nodes[robot, shape] = self._scene.add_batched_meshes_simple(
                f"/markers/{self._segments.get(robot) or node_name(robot)}/{shape}",
                vertices,
                faces,
                batched_wxyzs=wxyzs,
                batched_positions=positions,
                batched_colors=colors,
                lod="off",
                cast_shadow=False,
            )
            if self._pick is not None:
                clicked = functools.partial(self._clicked, robot, shape)
                adapter.accept_click(self._server, self.nodes[robot, shape], clicked)
            return
        node.batched_positions = positions
        node.batched_wxyzs = wxyzs
        node.batched_colors = colors
        node.visible = bool(len(chosen))

    def _clicked(self, robot: str, shape: str, client: int, instance: int | None) -> None:
        if instance is not None and self._pick is not None:
            self._pick(robot, shape, instance)


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
