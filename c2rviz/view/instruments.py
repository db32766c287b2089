"""The page as an instrument: every robot's history, plots, readout and ghost, and the timeline.

``Instruments`` belongs to the ``ViserScene``: the scene hands it the world's
effects (each only records, in O(1)) and, in each send, asks it what time the
page shows (``shown``: None for now) and to draw what it owns:

* live, each robot's target ghost and path line while it travels (``ghost``),
  and, at most ``PLOT_HZ``/``READOUT_HZ`` a second, its plots and its readout
  (with the panel's pose text: text changing at every frame is unreadable and
  costs a message a frame); with many robots the plots of all together go out
  at most ``PLOTS_PER_S`` a second (each robot's in turn);
* looking back (the timeline at a time of the history), every robot as it was
  then: its links, markers and workcell objects from its ``RobotHistory``, its
  plots ending at that time, no ghost; the world goes on unseen, and its
  markers and objects are drawn again on the way back to live.

It wakes the scene for a send when something of its own is due later (a plot
held back by its rate, a refused target's end, a replay's next frame).
"""

from __future__ import annotations

import asyncio
import math
import time
from collections.abc import Callable, Mapping, Sequence

import viser

from ..collision.workcell import WorkcellObject
from ..errors import C2rvizError, PathCollides
from ..world.state import Marker
from ..world.world import World
from .cell_layers import WorkcellLayer
from .ghost import RobotGhost
from .history import RobotHistory
from .markers import MarkerLayer
from .page_input import PageInput
from .panel import RobotPanel, RobotReadout
from .plots import RobotPlots
from .robot_view import RobotView
from .timeline import Timeline


class Instruments:
    """The page's instruments; see the module docstring.

    Attributes:
        origin_s: The clock time the page's times count from (the server's start) [s].
        histories: Each robot's ``RobotHistory``, by name.
        plots: Each robot's ``RobotPlots``.
        readouts: Each robot's ``RobotReadout``.
        ghosts: Each robot's ``RobotGhost`` (path line, refused target).
        timeline: The page's ``Timeline``.
    """

    def __init__(
        self,
        server: viser.ViserServer,
        world: World,
        views: Mapping[str, RobotView],
        panels: Mapping[str, RobotPanel],
        markers: MarkerLayer,
        workcells: Mapping[str, WorkcellLayer],
        timeline: Timeline,
        velocities: bool,
    ) -> None:
        """Add the plots and readouts to the robots' folders.

        Args:
            server: The page's viser server.
            world: The world shown.
            views, panels, markers, workcells: The scene's layers (drawn into when the page
                looks back).
            timeline: The page's timeline (made first: it heads the panel).
            velocities: Show the velocity charts at first (moves take time).
        """
        self.world = world
        self.views, self.panels, self.markers, self.workcells = views, panels, markers, workcells
        self.origin_s = origin = timeline.origin_s
        self.histories: dict[str, RobotHistory] = {}
        self.plots: dict[str, RobotPlots] = {}
        self.readouts: dict[str, RobotReadout] = {}
        self.ghosts: dict[str, RobotGhost] = {}
        for name, state in world.robots.items():
            objects = self._objects_now(name)
            resting = not world.moving(name)
            self.histories[name] = RobotHistory(state, world.frame_s, origin, objects, resting)
            with panels[name].folder:
                self.readouts[name] = RobotReadout(server.gui, state.robot, len(world.robots))
                self.plots[name] = RobotPlots(  # right after the buttons: on a 900 px screen
                    server.gui,
                    state.robot,
                    origin,
                    velocities,
                    len(world.robots),
                    order=panels[name].buttons["stop"].order + 0.5,
                )
            self.ghosts[name] = RobotGhost(server, views[name])
        self.timeline = timeline
        timeline.follow(self._span)
        self._request: Callable[[], None] = lambda: None
        self._loop: asyncio.AbstractEventLoop | None = None
        self._wake: asyncio.TimerHandle | None = None
        self._wake_at = math.inf
        self._replot: set[str] = set(world.robots)  # plots to draw though the time is the same
        self._reread: set[str] = set(world.robots)  # readouts to draw
        self._past: float | None = None  # the time drawn while looking back
        self._marker_keys: dict[str, tuple[int, int]] = {}
        self._objects_shown: dict[str, list[WorkcellObject]] = {}
        self._names = list(self.histories)  # the order draw() takes them in, from _turn
        self._turn = 0

    def bind(self, page_input: PageInput) -> None:
        """Let the page's controls set the plots and the timeline."""
        for name, plots in self.plots.items():
            redraw = self._redraw(name)
            for box in (plots.shown, plots.pause, plots.velocities, *plots.joints):
                page_input.add_setting(box, lambda value: None, redraw)
            page_input.add_setting(plots.window, plots.set_window, redraw)
        line = self.timeline
        after = self._retime
        page_input.add_setting(line.slider, line.seek, after)
        page_input.add_setting(line.speed_slider, line.set_speed, after)
        page_input.add_setting(line.buttons, lambda value: line.press(value, _now()), after, True)

    def start(self, loop: asyncio.AbstractEventLoop, request: Callable[[], None]) -> None:
        """Wake the scene through ``request`` on ``loop`` from now on."""
        self._loop, self._request = loop, request

    def stop(self) -> None:
        if self._wake is not None:
            self._wake.cancel()
            self._wake = None
        self._loop = None

    # the world's effects (the asyncio thread; O(1) each)

    def on_joints(self, robot: str, q: Sequence[float], t: float) -> None:
        history = self.histories.get(robot)
        if history is not None:
            history.add(q, t, not self.world.moving(robot))
            self._reread.add(robot)

    def on_marker(self, robot: str, marker: Marker) -> None:
        if robot in self.histories:
            self.histories[robot].mark(marker, self.world.clock.now())

    def on_clear_markers(self, robot: str) -> None:
        if robot in self.histories:
            self.histories[robot].clear(self.world.clock.now())

    def on_objects(self, robot: str, objects: Sequence[WorkcellObject]) -> None:
        if robot in self.histories:
            self.histories[robot].objects(objects, self.world.clock.now())

    def on_refused(self, robot: str, line: str, error: C2rvizError) -> None:
        readout = self.readouts.get(robot)
        if readout is None:
            return
        readout.refused(line, str(error))
        self._reread.add(robot)
        if isinstance(error, PathCollides) and error.target is not None:
            state = self.world.robots[robot]
            if len(error.target) == state.robot.n:
                self.ghosts[robot].refuse(error.target, error.pair, state.tool, _now())
        self._replot.add(robot)

    # what a send asks

    def shown(self) -> float | None:
        """The clock time the page shows (None: now), a replay advanced to it."""
        self.timeline.tick(_now())
        return self.timeline.time()

    def draw_live(self, robot: str) -> None:
        """``robot``'s target ghost and path line, as it travels now (if its ghost is on)."""
        state, travel = self.world.robots[robot], self.world.travel(robot)
        on = state.ghost and travel.active
        self.views[robot].show_target(state.target if on else None)
        now = self.world.clock.now()
        self.ghosts[robot].show_path(travel.path if on else None, state.tool, now)

    def draw_past(self, t: float) -> None:
        """Every robot, its markers and objects as they were at clock time ``t`` [s]."""
        if t == self._past:
            return
        self._past = t
        for name, history in self.histories.items():
            view = self.views[name]
            self.panels[name].show_pose(view.draw(history.at(t)))
            view.show_target(None)
            self.ghosts[name].show_path(None, self.world.robots[name].tool, t)
            key, markers = history.markers_at(t)
            if self._marker_keys.get(name) != key:
                self._marker_keys[name] = key
                self.markers.draw_these(name, markers)
            objects = history.objects_at(t)
            if self._objects_shown.get(name) is not objects:
                self._objects_shown[name] = objects
                self.workcells[name].show_objects(objects)
            self._replot.add(name)
            self._reread.add(name)

    def back_to_live(self) -> dict[str, list[WorkcellObject]] | None:
        """After looking back: redraw the held markers; return each robot's objects now, to
        draw (None if the page was live already)."""
        if self._past is None:
            return None
        self._past = None
        self._marker_keys.clear()
        self._objects_shown.clear()
        self.markers.redraw()
        self._replot.update(self.histories)
        self._reread.update(self.histories)
        return {name: self._objects_now(name) for name in self.histories}

    def draw(self, shown: float | None, deadline: float = math.inf) -> None:
        """The plots, readouts, refused targets and the timeline, each when due; then wake
        the scene for what is due later.

        Past ``deadline`` [s of ``time.perf_counter``] the robots left wait for the next
        send (they go first then), so a send of many robots' plots and readouts comes in
        turns."""
        now = _now()
        wait = math.inf
        names = self._names
        first = self._turn % len(names)
        for k in range(len(names)):
            name = names[(first + k) % len(names)]
            if k and time.perf_counter() > deadline:
                self._turn = first + k
                wait = 0.0
                break
            history = self.histories[name]
            state = self.world.robots[name]
            wait = min(wait, self.ghosts[name].expire(now, state.ghost and shown is None))
            plots = self.plots[name]
            end = history.end if shown is None else shown
            if (
                plots.shown.value
                and not plots.pause.value
                and (name in self._replot or plots.drawn_s != end)
            ):
                if plots.due(now):
                    plots.draw(history, end, now)
                    self._replot.discard(name)
                else:
                    wait = min(wait, plots.wait_s(now))
            if name in self._reread:
                if self.readouts[name].due(now):
                    self._reread.discard(name)
                    self._show_readout(name, shown, now)
                else:
                    wait = min(wait, self.readouts[name].wait_s(now))
        line = self.timeline
        if line.due(now):
            line.show(now)
        if line.playing:
            wait = min(wait, self.world.frame_s)
        elif not line.live:
            wait = min(wait, 1.0)  # the history's span moves on: show it
        self._wake_in(wait)

    # helpers

    def _show_readout(self, name: str, shown: float | None, now: float) -> None:
        state = self.world.robots[name]
        if shown is None:
            q = state.q
            seconds = self.world.travels.seconds_left(state)
            motion = f"moving, {seconds:.1f} s left" if self.world.moving(name) else "idle"
            at = None
        else:
            q = self.histories[name].at(shown)
            motion, at = "(looking back)", f"{shown - self.origin_s:.2f} s"
        ee = self.views[name].ee_pose(tuple(q))
        if shown is None:  # the panel's pose goes at the readout's pace too
            self.panels[name].show_pose(ee)
        self.readouts[name].show(q, ee * state.tool, motion, at, now)

    def _span(self) -> tuple[float, float]:
        """The times every robot's history covers: its latest start, and now [s]."""
        start = max(history.start for history in self.histories.values())
        return start, self.world.clock.now()

    def _objects_now(self, name: str) -> list[WorkcellObject]:
        mirrored = getattr(self.world, "objects", None)  # the page process's mirror
        if mirrored is not None:
            return list(mirrored.get(name, ()))
        model = self.world.contacts.models.get(name)
        return model.object_list() if model is not None else []

    def _redraw(self, name: str) -> Callable[[], None]:
        def redraw() -> None:
            self._replot.add(name)
            self._request()

        return redraw

    def _retime(self) -> None:
        self.timeline.show(_now(), force=True)
        self._replot.update(self.histories)
        self._reread.update(self.histories)
        self._request()

    def _wake_in(self, seconds: float) -> None:
        """Ask for a send ``seconds`` from now [s of real time] (the earliest wins)."""
        loop = self._loop
        if loop is None or not math.isfinite(seconds):
            return
        when = loop.time() + max(seconds, 0.0)
        if self._wake is not None and self._wake_at <= when:
            return
        if self._wake is not None:
            self._wake.cancel()
        self._wake_at = when
        self._wake = loop.call_at(when, self._woken)

    def _woken(self) -> None:
        self._wake, self._wake_at = None, math.inf
        self._request()


def _now() -> float:
    """Real time [s]: what the page's rates and a replay's pace are counted in."""
    return time.monotonic()
