"""What the page's controls do: each becomes a line on the page's session.

The page is a source of commands like any TCP client: a slider dragged to 30
becomes ``move 1 30.0`` on that robot's page session (source ``page``,
degrees mode), the Home / Random / Stop buttons ``home`` / ``rand`` /
``stop``, the speed slider ``speed 40.0``, the Trail checkbox ``trail on`` /
``trail off``, the Ghost checkbox ``ghost on`` / ``ghost off``. The session
checks them; a refused value is sent back to the tab as the true one, and so is
a value the door drops (NaN, a word). The page's own controls (the plots', the
timeline's) go the same way and are checked where they are applied
(``add_setting``): a value out of range is refused and shown true again. A click
on a marker chooses it in its robot's folder; "Go to marker" then runs
``moveto marker N`` (N: where the chosen marker stands now among the robot's
markers).

viser's door (``adapter.accept_input``) hands each value to a callback on viser's thread
and nowhere else; the callback hands it to the loop through a ``Handoff``: however fast a
page sends, a control costs the loop at most one command per loop turn (the latest value
wins; a click while one waits adds nothing). Marker clicks come the same way, one per
robot per loop turn.

``Handoff`` takes values from viser's thread to the asyncio loop: the newest per control,
one run per turn. viser calls our callbacks on its own thread; the world lives on the
asyncio loop. ``Handoff.put(key, value)`` (viser's thread) keeps only the newest value of
each key and, if none was waiting, asks the loop to run it: however fast a page sends, a
control costs the loop at most one run per loop turn (the latest value wins). ``run(key,
value)`` is then called on the loop with the value waiting at that moment. Everything
shared between the two threads is behind ``lock``.
"""

from __future__ import annotations

import asyncio
import contextlib
import functools
import logging
import threading
from collections.abc import Awaitable, Callable, Hashable
from typing import Any, Generic, TypeVar

import viser

from ..errors import C2rvizError, MotionInterrupted
from ..session.session import Session
from . import adapter
from .door_rules import RateLimitedLog
from .markers import MarkerLayer
from .panel import RobotPanel

log = logging.getLogger("c2rviz.view")

Apply = Callable[[int, Any], None]
GONE = "the chosen marker is gone (cleared, or past the newest markers kept)"


class PageInput:
    """The page's controls, bound to sessions; see the module docstring.

    Attributes:
        refused: Page commands the sessions refused so far.
        picks: Marker clicks run so far (clicks that came while one waited count once).
    """

    def __init__(self, server: viser.ViserServer, markers: MarkerLayer) -> None:
        self._server = server
        self._markers = markers
        self._panels: dict[str, RobotPanel] = {}
        self._handoff: Handoff[Any, tuple[Apply, int, Any]] = Handoff(self._run)
        self._log = RateLimitedLog(log)
        self.refused = 0
        self.picks = 0

    def start(self, loop: asyncio.AbstractEventLoop) -> None:
        """Run page input on ``loop`` from now on (earlier input is dropped)."""
        self._handoff.start(loop)

    def stop(self) -> None:
        """Drop page input from now on."""
        self._handoff.stop()

    # what is bound

    def add_robot(self, panel: RobotPanel, session: Session) -> None:
        """Bind one robot's folder to its page session."""
        for i, slider in enumerate(panel.sliders):
            self._bind(slider, functools.partial(self._move, panel, session, i))
        self._bind(panel.speed, functools.partial(self._speed, panel, session))
        for line, button in panel.buttons.items():
            self._bind(button, functools.partial(self._click, session, line))
        self._bind(panel.trail, functools.partial(self._trail, panel, session))
        self._bind(panel.ghost, functools.partial(self._ghost, panel, session))
        self._bind(panel.goto, functools.partial(self._goto, panel, session))
        self._panels[session.state.name] = panel

    def add_toggle(self, checkbox: Any, on_change: Callable[[bool], None]) -> None:
        """Bind a checkbox: ``on_change(shown)``, then every tab shows the value."""

        def toggle(client: int, value: Any) -> None:
            on_change(bool(value))
            adapter.set_gui_value(checkbox, bool(value), exclude_client=client)

        self._bind(checkbox, toggle)

    def add_setting(
        self,
        handle: Any,
        apply: Callable[[Any], object],
        after: Callable[[], None],
        button: bool = False,
    ) -> None:
        """Bind a control of the page's own (a plot's window, the timeline): ``apply(value)``
        takes the value, or raises a ``C2rvizError`` to refuse it (the control then shows
        the true value again); every tab is shown a value taken (not a ``button``'s click),
        and ``after()`` runs (a redraw)."""

        def run(client: int, value: Any) -> None:
            try:
                apply(value)
            except C2rvizError as exc:
                self._refuse(f"{handle.label} {value!r}", exc)
                if not button:
                    adapter.set_gui_value(handle, handle.value, force=True)
            else:
                if not button:
                    adapter.set_gui_value(handle, value, exclude_client=client)
            after()

        self._bind(handle, run)

    def busy(self, handle: Any) -> bool:
        """Whether a page value for ``handle`` waits to be run (leave the control alone)."""
        return self._handoff.waiting(id(handle))

    # viser's thread: record, and wake the loop once

    def pick(self, robot: str, shape: str, instance: int) -> None:
        """A click on ``instance`` of ``robot``'s ``shape`` markers (``MarkerLayer``'s pick)."""
        self._arrived(("pick", robot), self._picked, 0, (robot, shape, instance))

    def _bind(self, handle: Any, apply: Apply) -> None:
        arrived = functools.partial(self._arrived, id(handle), apply)
        refused = functools.partial(self._arrived, ("refused", id(handle)), self._resend(handle))
        adapter.accept_input(self._server, handle, arrived, lambda client: refused(client, None))

    @staticmethod
    def _resend(handle: Any) -> Apply:
        """Show every tab ``handle``'s true value (after a value the door dropped)."""

        def resend(client: int, value: Any) -> None:
            adapter.set_gui_value(handle, handle.value, force=True)

        return resend

    def _arrived(self, key: Any, apply: Apply, client: int, value: Any) -> None:
        self._handoff.put(key, (apply, client, value))

    # the asyncio thread

    @staticmethod
    def _run(key: Any, waiting: tuple[Apply, int, Any]) -> None:
        apply, client, value = waiting
        apply(client, value)

    def _move(self, panel: RobotPanel, session: Session, index: int, client: int, v: Any) -> None:
        ok = self._line(session, f"move {index} {float(v)!r}")
        panel.answer(index, float(v), session.state.target[index], client, force=not ok)

    def _speed(self, panel: RobotPanel, session: Session, client: int, v: Any) -> None:
        ok = self._line(session, f"speed {float(v)!r}")
        if ok and session.speed == float(v):
            adapter.set_gui_value(panel.speed, session.speed, exclude_client=client)
        else:
            adapter.set_gui_value(panel.speed, session.speed, force=True)

    def _click(self, session: Session, line: str, client: int, value: Any) -> None:
        if value is True:
            self._line(session, line)

    def _picked(self, client: int, where: tuple[str, str, int]) -> None:
        robot, shape, instance = where
        self.picks += 1
        marker = self._markers.marker_at(robot, shape, instance)
        panel = self._panels.get(robot)
        if marker is not None and panel is not None:
            panel.choose(marker)
            self._server.flush()

    def _goto(self, panel: RobotPanel, session: Session, client: int, value: Any) -> None:
        chosen = panel.chosen
        if value is not True or chosen is None:
            return
        markers = session.state.markers
        number = next((n for n, m in enumerate(markers, start=1) if m is chosen), None)
        if number is None:
            self._refuse("Go to marker", C2rvizError(GONE))
            panel.choose(None)
            return
        self._line(session, f"moveto marker {number}")

    def _trail(self, panel: RobotPanel, session: Session, client: int, value: Any) -> None:
        self._line(session, "trail on" if value is True else "trail off")
        on = session.state.name in session.services.trails.trails
        adapter.set_gui_value(panel.trail, on, force=True)

    def _ghost(self, panel: RobotPanel, session: Session, client: int, value: Any) -> None:
        self._line(session, "ghost on" if value is True else "ghost off")
        adapter.set_gui_value(panel.ghost, session.state.ghost, force=True)

    def _line(self, session: Session, line: str) -> bool:
        """Run ``line`` on ``session``; whether it was accepted (a later reply: so far)."""
        try:
            reply = session.run(line)
        except C2rvizError as exc:
            self._refuse(line, exc)
            return False
        if isinstance(reply, Awaitable):  # a reply that comes later: the page does not wait
            future = asyncio.ensure_future(reply)
            future.add_done_callback(functools.partial(self._answered, line))
        return True

    def _answered(self, line: str, future: asyncio.Future[Any]) -> None:
        error = None if future.cancelled() else future.exception()
        if isinstance(error, MotionInterrupted):
            return  # a newer move took over, or a stop: the page's moves replace each other
        if isinstance(error, C2rvizError):
            self._refuse(line, error)
        elif error is not None:
            self._log.warning("failed", f"a page command failed: {line}: {error!r}")

    def _refuse(self, line: str, error: C2rvizError) -> None:
        self.refused += 1
        self._log.warning("refused", f"refused from the page: {line}: {error}")


K = TypeVar("K", bound=Hashable)
V = TypeVar("V")


class Handoff(Generic[K, V]):
    """The newest value of each key, handed from viser's thread to the loop."""

    def __init__(self, run: Callable[[K, V], None]) -> None:
        """Set up; ``run(key, value)`` is called on the loop for each value handed over."""
        self.lock = threading.Lock()
        self._run = run
        self._loop: asyncio.AbstractEventLoop | None = None
        self._pending: dict[K, V] = {}

    def start(self, loop: asyncio.AbstractEventLoop) -> None:
        """Hand values to ``loop`` from now on (earlier ones were dropped)."""
        self._loop = loop

    def stop(self) -> None:
        """Drop values from now on."""
        self._loop = None

    @property
    def running(self) -> bool:
        """Values are handed over (between ``start`` and ``stop``)."""
        return self._loop is not None

    def put(self, key: K, value: V) -> None:
        """(viser's thread) ``value`` is the newest of ``key``; wake the loop if it must."""
        loop = self._loop
        if loop is None:
            return
        with self.lock:
            first = key not in self._pending
            self._pending[key] = value
        if first:
            with contextlib.suppress(RuntimeError):  # the loop is closed: we stop
                loop.call_soon_threadsafe(self._due, key)

    def waiting(self, key: K) -> bool:
        """A value of ``key`` waits to be run."""
        return key in self._pending

    def take(self, key: K) -> V | None:
        """(the loop) The value of ``key`` waiting now, taken; None if none waits."""
        with self.lock:
            return self._pending.pop(key, None)

    def defer(self, key: K, value: V) -> None:
        """(the loop) Keep ``value`` waiting, untouched, for a later ``take`` (unless a newer
        value of ``key`` came meanwhile, which wins)."""
        with self.lock:
            self._pending.setdefault(key, value)

    def _due(self, key: K) -> None:
        if self._loop is None:
            return
        value = self.take(key)
        if value is not None:
            self._run(key, value)
