"""Markers in the page: one batched node per robot and shape, rebuilt once per frame.

A marker costs O(1) where the command runs: ``add`` writes it into its
robot's ring of ``MAX_MARKERS`` slots (the oldest is overwritten), and
``clear`` forgets them all. Once per frame the send calls ``draw``, which
hands each changed robot's markers, shape by shape, to one viser batched-mesh
node (``/markers/<robot>/<shape>``) as new instance arrays. The node's state
is replaced, never removed and added again, so viser's buffer holds one
update per node whatever the number of markers sent.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Iterable
from typing import Any

import numpy as np
import viser

from ..protocol.grammar import MARKER_SHAPES
from ..world.observer import MAX_MARKERS, Marker
from . import adapter
from .marker_meshes import marker_mesh
from .robot_view import node_name

__all__ = ["MarkerLayer"]


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
