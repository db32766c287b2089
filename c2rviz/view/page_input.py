"""What the page's controls do: each becomes a line on the page's session.

The page is a source of commands like any TCP client: a slider dragged to 30
becomes ``move 1 30.0`` on that robot's page session (source ``page``,
degrees mode), the Home / Random / Stop buttons ``home`` / ``rand`` /
``stop``, the speed slider ``speed 40.0``, the Trail checkbox ``trail on`` /
``trail off``. The session checks them; a refused
value is sent back to the tab as the true one.

viser's door (``adapter.accept_input``) hands each value to a callback on
viser's thread and nowhere else. Here the callback only records the newest
value of its control and, if none was waiting, asks the asyncio loop to run
it: however fast a page sends, a control costs the loop at most one command
per loop turn (the latest value wins; a click while one waits adds nothing).
"""

from __future__ import annotations

import asyncio
import contextlib
import functools
import logging
import threading
from collections.abc import Callable
from typing import Any

import viser

from ..errors import C2rvizError
from ..session import Session
from ..trail import TrailKeeper
from . import adapter
from .panel import RobotPanel
from .ratelog import RateLimitedLog

__all__ = ["PageInput"]

log = logging.getLogger("c2rviz.view")

Apply = Callable[[int, Any], None]


class PageInput:
    """The page's controls, bound to sessions; see the module docstring.

    Attributes:
        refused: Page commands the sessions refused so far.
    """

    def __init__(self, server: viser.ViserServer) -> None:
        self._server = server
        self._loop: asyncio.AbstractEventLoop | None = None
        self._lock = threading.Lock()
        self._pending: dict[int, tuple[Apply, int, Any]] = {}
        self._log = RateLimitedLog(log)
        self.refused = 0

    def start(self, loop: asyncio.AbstractEventLoop) -> None:
        """Run page input on ``loop`` from now on (earlier input is dropped)."""
        self._loop = loop

    def stop(self) -> None:
        """Drop page input from now on."""
        self._loop = None

    # what is bound

    def add_robot(self, panel: RobotPanel, session: Session) -> None:
        """Bind one robot's folder to its page session."""
        for i, slider in enumerate(panel.sliders):
            self._bind(slider, functools.partial(self._move, panel, session, i))
        self._bind(panel.speed, functools.partial(self._speed, panel, session))
        for line, button in panel.buttons.items():
            self._bind(button, functools.partial(self._click, session, line))
        self._bind(panel.trail, functools.partial(self._trail, panel, session))

    def add_toggle(self, checkbox: Any, on_change: Callable[[bool], None]) -> None:
        """Bind a checkbox: ``on_change(shown)``, then every tab shows the value."""

        def toggle(client: int, value: Any) -> None:
            on_change(bool(value))
            adapter.set_gui_value(checkbox, bool(value), exclude_client=client)

        self._bind(checkbox, toggle)

    def busy(self, handle: Any) -> bool:
        """Whether a page value for ``handle`` waits to be run (leave the control alone)."""
        return id(handle) in self._pending

    # viser's thread: record, and wake the loop once

    def _bind(self, handle: Any, apply: Apply) -> None:
        key = id(handle)

        def arrived(client: int, value: bool | float) -> None:
            loop = self._loop
            if loop is None:
                return
            with self._lock:
                first = key not in self._pending
                self._pending[key] = (apply, client, value)
            if first:
                with contextlib.suppress(RuntimeError):  # the loop is closed: we stop
                    loop.call_soon_threadsafe(self._run, key)

        adapter.accept_input(self._server, handle, arrived)

    # the asyncio thread

    def _run(self, key: int) -> None:
        with self._lock:
            apply, client, value = self._pending.pop(key)
        if self._loop is not None:
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

    def _trail(self, panel: RobotPanel, session: Session, client: int, value: Any) -> None:
        self._line(session, "trail on" if value is True else "trail off")
        on = session.state.name in TrailKeeper.of(session.world).trails
        adapter.set_gui_value(panel.trail, on, force=True)

    def _line(self, session: Session, line: str) -> bool:
        """Run ``line`` on ``session``; whether it was accepted."""
        try:
            reply = session.run(line)
        except C2rvizError as exc:
            self.refused += 1
            self._log.warning("refused", f"refused from the page: {line}: {exc}")
            return False
        if asyncio.isfuture(reply):  # a reply that comes later: the page does not wait
            reply.add_done_callback(_consume)
        return True


def _consume(future: asyncio.Future[Any]) -> None:
    if not future.cancelled():
        future.exception()  # retrieved: no "exception never retrieved" at exit
