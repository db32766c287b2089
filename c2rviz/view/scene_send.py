"""When and how the page is sent what changed (``ViserScene``'s sends, kept apart from its
set-up and the effects it notes): when, ``SendScheduler``; how, ``SceneSends``: the robots
changed since the last send, in slices of ``SLICE_S`` (each an atomic batch, the loop
taking a turn between them), then the markers, the workcells, parts, goals, cameras and
trails, the instruments and the state panel; or, while the timeline looks back, every
robot as it was at that time.

At most once per frame, the latest state wins. The world tells the view of every change,
possibly hundreds of thousands of times a second; each call only records the new state and
asks for a send. A ``SendScheduler`` runs the send on the asyncio loop at most once per
period (``1/hz``): a lone change after a quiet spell goes out at once, a flood goes out
once per period, and a request while one is due adds nothing.

A send may come in slices: ``send`` returns True while work is left (many
robots to draw), and its next slice runs at the loop's next turn, after
whatever else waits (a client's line), so no slice holds the loop long. The
pace adapts to the cost: the next send starts no sooner than the last one's
time at work after it ended (``REST_PER_WORK``), so however many robots there
are, sends take at most about half of the loop and every robot still gets every
frame there is.
"""

from __future__ import annotations

import asyncio
import math
import time
from collections import deque
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING

from ..collision.workcell import WorkcellObject
from ..world.cameras import Camera
from ..world.part_rules import Goal
from ..world.parts import Part
from ..world.world import sight

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


REST_PER_WORK = 1.0
"""The loop's time left to other work after a send, per second the send worked."""


class SendScheduler:
    """Calls ``send`` on the loop at most once per ``period_s``; see the module docstring.

    Attributes:
        period_s: Shortest time between two sends' starts [s].
        sends: How many sends have run to their end.
        rest_per_work: The loop's time left to other work after a send, per second the
            send worked (``REST_PER_WORK``; the page process, which serves no client,
            leaves less).
        work_s: The last send's time at work, its slices summed [s of this thread's CPU
            time: a wait for the GIL while viser's thread encodes is not work].
    """

    def __init__(self, period_s: float, send: Callable[[], bool]) -> None:
        """``send`` draws (a slice of) what changed; it returns True if work is left."""
        self.period_s = period_s
        self.sends = 0
        self.work_s = 0.0
        self.rest_per_work = REST_PER_WORK
        self._send = send
        self._loop: asyncio.AbstractEventLoop | None = None
        self._timer: asyncio.Handle | None = None
        self._last_s = -math.inf  # the last send's start [s of the loop's clock]
        self._rest_until = -math.inf  # no send before this [s of the loop's clock]
        self._slicing = False  # a send is under way: its next slice is queued
        self._again = False  # asked for while slicing
        self._work = 0.0
        self._stopped = False

    def start(self, loop: asyncio.AbstractEventLoop) -> None:
        """Send on ``loop`` from now on (requests before this wait for it)."""
        self._loop = loop
        self.request()

    def request(self) -> None:
        """Send now if the last send is a period old, else once it is; never twice."""
        loop = self._loop
        if self._slicing:
            self._again = True  # after this send, for what changed while it ran
            return
        if self._timer is not None or loop is None or self._stopped:
            return
        due = max(self._last_s + self.period_s, self._rest_until)
        if loop.time() >= due:
            self._timer = loop.call_soon(self._run)
        else:
            self._timer = loop.call_at(due, self._run)

    def stop(self) -> None:
        """No more sends; later calls do nothing."""
        self._stopped = True
        if self._timer is not None:
            self._timer.cancel()
            self._timer = None

    def _run(self) -> None:
        self._timer = None
        loop = self._loop
        if self._stopped or loop is None:
            return
        if not self._slicing:
            self._last_s = loop.time()
            self._work = 0.0
        began = time.thread_time()
        more = False
        try:
            more = self._send()
        finally:
            self._work += time.thread_time() - began
            if more and not self._stopped:
                self._slicing = True
                self._timer = loop.call_soon(self._run)
            else:
                self._end(loop)

    def _end(self, loop: asyncio.AbstractEventLoop) -> None:
        """A send is over: rest as long as it worked, then send again if asked meanwhile."""
        self._slicing = False
        self.work_s = self._work
        self._rest_until = loop.time() + self.rest_per_work * self._work
        self.sends += 1
        if self._again:
            self._again = False
            self.request()
