"""How a send of the page draws (``ViserScene``'s sends, kept apart from its set-up and
the effects it notes): the robots changed since the last send, in slices of ``SLICE_S``
(each an atomic batch, the loop taking a turn between them), then the markers, the
workcells, parts, goals, cameras and trails, the instruments and the state panel; or,
while the timeline looks back, every robot as it was at that time.
"""

from __future__ import annotations

import time
from collections import deque
from collections.abc import Sequence
from typing import TYPE_CHECKING

from ..collision.workcell import WorkcellObject
from ..world.camera_sight import sight
from ..world.cameras import Camera
from ..world.goals import Goal
from ..world.parts import Part

if TYPE_CHECKING:
    import viser

    from ..session.services import Services
    from ..world.world import World
    from .cell_layers import CameraLayer, PartsLayer, TrailLayer, WorkcellLayer
    from .handle import ToolHandles
    from .instruments import Instruments
    from .markers import MarkerLayer
    from .page_input import PageInput
    from .panel import RobotPanel, StatePanel
    from .robot_view import RobotView

__all__ = ["SLICE_S", "SceneSends"]

SLICE_S = 0.002
"""Longest run of drawing robots before the loop gets a turn [s] (a send of many robots
comes in slices, so a client's line never waits behind a whole frame). A scene's
``slice_s`` is this unless set (the page process, whose loop serves no client, sets a
longer one: fewer atomic batches, each of which wakes viser's thread once)."""


class SceneSends:
    """The sends of a ``ViserScene`` (which sets every attribute named here)."""

    server: viser.ViserServer
    services: Services
    world: World
    views: dict[str, RobotView]
    panels: dict[str, RobotPanel]
    markers: MarkerLayer
    workcells: dict[str, WorkcellLayer]
    trails: TrailLayer
    parts: PartsLayer
    cameras: CameraLayer
    handles: ToolHandles
    page_input: PageInput
    instruments: Instruments
    state_panel: StatePanel
    slice_s: float
    _stopped: bool
    _dirty: set[str]
    _drawing: list[str] | None
    _commands: deque[tuple[str, bool]]
    _client_count: int
    _state_dirty: bool
    _objects: dict[str, Sequence[WorkcellObject]]
    _collisions: dict[str, Sequence[tuple[str, str]]]
    _parts: list[Part] | None
    _goals: list[Goal] | None
    _cameras: list[Camera] | None

    def _send(self) -> bool:
        """Draw whatever changed since the last send, in one atomic batch per slice.

        A send draws each robot changed at its start once; after ``slice_s`` of drawing
        robots it returns True, the robots left for its next slice (the scheduler runs
        it at the loop's next turn). The last slice draws the rest: markers, workcells,
        instruments, the state panel.
        """
        if self._stopped:
            return False
        world, instruments = self.world, self.instruments
        began = time.perf_counter()
        with self.server.atomic():
            shown = instruments.shown()  # None: now; else the time the page looks back at
            if shown is None:
                if self._drawing is None:  # a new send: the robots changed by now
                    objects_now = instruments.back_to_live()
                    if objects_now is not None:  # back from looking back: all, as it is now
                        self._objects.update(objects_now)
                        self._dirty.update(world.robots)
                    self._drawing, self._dirty = list(self._dirty), set()
                drew = bool(self._drawing)
                if self._draw_robots(began + self.slice_s):
                    return True  # robots left for the next slice
                if drew and time.perf_counter() > began + self.slice_s / 2:
                    self._drawing = []  # all drawn: the rest gets a slice of its own
                    return True
                self.markers.draw()
            else:
                if self._drawing:  # looked back mid-send: those robots wait for live
                    self._dirty.update(self._drawing)
                instruments.draw_past(shown)
            self._drawing = None
            for name in self.handles.due():
                if name in world.robots:
                    self.handles.draw(world.robots[name])
            self._draw_workcells(shown is None)
            instruments.draw(shown, time.perf_counter() + self.slice_s)
            if self._state_dirty:
                self._state_dirty = False
                self.state_panel.show(self._client_count, self._commands)
        self.server.flush()
        return False

    def _draw_robots(self, deadline: float) -> bool:
        """Draw the robots of this send until ``deadline`` [s of ``time.perf_counter``],
        at least one.

        Returns:
            Whether robots are left for the next slice.
        """
        drawing = self._drawing
        assert drawing is not None
        world, busy, instruments = self.world, self.page_input.busy, self.instruments
        while drawing:
            state = world.robots.get(drawing.pop())
            if state is None:
                continue
            name = state.name
            view, panel = self.views[name], self.panels[name]
            ee = view.draw(state.q, state.opening)
            instruments.draw_live(name)
            panel.show_joints(state.target, busy)
            panel.show_motion(world.moving(name), world.travels.seconds_left(state))
            self.handles.draw(state, ee)
            if drawing and time.perf_counter() >= deadline:
                return True
        return False

    def _draw_workcells(self, live: bool) -> None:
        """The objects (``live``: looking back draws its own) and collisions that changed,
        and the trails if they moved."""
        if live:
            for name, objects in self._objects.items():
                if name in self.workcells:
                    self.workcells[name].show_objects(objects)
            self._objects.clear()
            if self._parts is not None:
                self.parts.show_parts(self._parts)
                self._parts = None
            if self._goals is not None:
                self.parts.show_goals(self._goals, self.world.parts.parts.all())
                self._goals = None
            if self._cameras is not None:
                seen = {
                    c.name: [s.name for s in sight(self.world, c.name, noisy=False)]
                    for c in self._cameras
                }
                self.cameras.show(self._cameras, self.world.clock.now(), seen)
                self._cameras = None
        for name, pairs in self._collisions.items():
            if name in self.workcells:
                self.workcells[name].show_collisions(pairs)
                self.panels[name].show_collisions(pairs)
        self._collisions.clear()
        keeper = self.services.trails
        if keeper.changed != self.trails.drawn:
            for name, panel in self.panels.items():
                panel.show_trail(name in keeper.trails)
            self.trails.draw(keeper)
