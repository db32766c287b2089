"""The timeline: look back through the page's history while the robots go on.

The ``Timeline`` folder holds a ``Time s`` slider over the history the page
keeps (seconds since the server started, the times of ``watch``'s ``state``
lines; ``history.HISTORY_S`` at most), the time
shown, the replay buttons (a frame back, play/pause, a frame forward, live) and
a ``Speed x`` slider (0.25 to 4). Moving the slider (or stepping) looks back: the page draws
every robot, its markers and objects and its plots as they were at that time,
while the world goes on unseen; play replays from there at the chosen speed and
becomes live again on reaching now; live returns at once. Like every
control of the page, the timeline is the page's: all tabs look back together.

Everything here is pure bookkeeping on the clock's times (``seek``, ``step``,
``tick``); ``PageValueError`` refuses a time outside the history or a speed outside
0.25..4, and the page then shows the true value again.

Every value the page's own controls set (a plot's window, the timeline's time and speed)
is checked so (``within``): one out of range is refused with a message naming the range,
and the control goes back to the true value.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import viser

from ..errors import C2rvizError
from . import adapter

SPEED_RANGE = (0.25, 4.0)
"""Slowest and fastest replay of the history."""
SHOW_HZ = 2.0
BUTTONS = ("◀", "play/pause", "▶", "live")
"""The replay buttons: a frame back, play or pause, a frame forward, live."""
"""Updates a second of the slider's range and the time shown, at most."""


class Timeline:
    """The page's timeline; see the module docstring.

    Attributes:
        origin_s: The clock time the page's times count from [s].
        live: The page shows now.
        shown_s: The clock time shown when not live [s].
        playing: Replaying from ``shown_s`` at ``speed``.
        speed: Replay speed (1: real time).
        frame_s: One step of ``step`` [s] (a frame of the world).
    """

    def __init__(self, gui: viser.GuiApi, origin_s: float, frame_s: float) -> None:
        self.origin_s = origin_s
        self.frame_s = frame_s
        self.live = True
        self.shown_s = origin_s
        self.playing = False
        self.speed = 1.0
        self._span = (origin_s, origin_s)
        self._source: Callable[[], tuple[float, float]] = lambda: (origin_s, origin_s)
        self._shown_at = -math.inf
        self._played_at: float | None = None
        with gui.add_folder("Timeline", expand_by_default=True):
            self.slider: Any = gui.add_slider(
                "Time s",
                min=0.0,
                max=1.0,
                step=0.01,
                initial_value=1.0,
                hint="look back: seconds since the server started, as watch's state lines "
                "(the page keeps the last 5 minutes); the robots go on meanwhile",
            )
            self.readout: Any = gui.add_text("Shown", "live", disabled=True)
            self.buttons: Any = gui.add_button_group(
                "Replay",
                BUTTONS,
                hint="a frame back, play or pause from the time shown, a frame on, live again",
            )
            low, high = SPEED_RANGE
            self.speed_slider: Any = gui.add_slider(
                "Speed x",
                min=low,
                max=high,
                step=0.25,
                initial_value=1.0,
                hint=f"replay speed, {low:g} to {high:g} times real time",
            )

    # what the controls do (on the loop; ``start``/``end`` are the history's span)

    def follow(self, span: Callable[[], tuple[float, float]]) -> None:
        """Ask ``span()`` for the history's first and last times [s of the clock]."""
        self._source = span

    def span(self) -> tuple[float, float]:
        """The history's span now [s of the clock] (what ``follow`` gave says)."""
        start, end = self._source()
        self._span = (start, max(start, end))
        if not self.live and self.shown_s < start:
            self.shown_s = start  # what was shown has left the history
        return self._span

    def seek(self, seconds: float) -> None:
        """Show the time ``seconds`` after ``origin_s``; the end of the history is live.

        Raises:
            PageValueError: outside the history.
        """
        start, end = self.span()
        low, high = start - self.origin_s, end - self.origin_s
        within("timeline time", seconds, math.floor(low * 100) / 100, high + 0.01, " s")
        t = min(max(seconds + self.origin_s, start), end)
        self.playing = False
        if t >= end:
            self.go_live()
        else:
            self.live, self.shown_s = False, t

    def step(self, frames: int) -> None:
        """Show ``frames`` frames later (earlier if negative) than the time shown."""
        start, end = self.span()
        here = end if self.live else self.shown_s
        self.playing = False
        t = min(max(here + frames * self.frame_s, start), end)
        if t >= end and frames > 0:
            self.go_live()
        else:
            self.live, self.shown_s = False, t

    def set_speed(self, speed: float) -> None:
        """Replay at ``speed`` times real time.

        Raises:
            PageValueError: outside ``SPEED_RANGE``.
        """
        self.speed = within("replay speed", speed, *SPEED_RANGE, "x")

    def press(self, button: str, now_s: float) -> None:
        """One of ``BUTTONS`` was clicked at real time ``now_s`` [s]."""
        if button == BUTTONS[0]:
            self.step(-1)
        elif button == BUTTONS[1]:
            self.toggle_play(now_s)
        elif button == BUTTONS[2]:
            self.step(1)
        elif button == BUTTONS[3]:
            self.go_live()

    def toggle_play(self, now_s: float) -> None:
        """Play from the time shown, or pause; ``now_s`` is the real time [s]."""
        if self.live:
            return  # live already plays
        self.playing = not self.playing
        self._played_at = now_s if self.playing else None

    def go_live(self) -> None:
        self.live = True
        self.playing = False
        self._played_at = None

    def tick(self, now_s: float) -> bool:
        """Advance a replay to real time ``now_s`` [s]; whether the time shown moved."""
        if not self.playing or self.live:
            return False
        last, self._played_at = self._played_at or now_s, now_s
        self.shown_s += (now_s - last) * self.speed
        if self.shown_s >= self.span()[1]:
            self.go_live()
        return True

    def time(self) -> float | None:
        """The clock time shown [s], or None when live."""
        return None if self.live else self.shown_s

    # showing

    def due(self, now_s: float) -> bool:
        return now_s - self._shown_at >= 1.0 / SHOW_HZ

    def show(self, now_s: float, force: bool = False) -> None:
        """The slider's range, its value, the time shown and the Play button's label."""
        self._shown_at = now_s
        start, end = self.span()
        low = math.floor((start - self.origin_s) * 100) / 100
        high = max(math.ceil((end - self.origin_s) * 100) / 100, low + 0.01)
        if (self.slider.min, self.slider.max) != (low, high):
            self.slider.min, self.slider.max = low, high
        value = high if self.live else round(self.shown_s - self.origin_s, 2)
        adapter.set_gui_value(self.slider, min(max(value, low), high), force=force)
        if self.live:
            text = "live"
        else:
            ago = end - self.shown_s
            text = f"{self.shown_s - self.origin_s:.2f} s ({ago:.2f} s ago)"
            text += f", playing {self.speed:g}x" if self.playing else ""
        self.readout.value = text


class PageValueError(C2rvizError):
    """A page control set to a value it does not take."""

    def __init__(self, control: str, value: float, valid: str) -> None:
        self.control = control
        self.value = value
        self.valid = valid
        super().__init__(f"{control} {value:g} is not {valid}")


def within(control: str, value: float, low: float, high: float, unit: str = "") -> float:
    """``value`` if it is a finite number in ``low..high``.

    Raises:
        PageValueError: naming ``control`` and the range (in ``unit``).
    """
    if not (math.isfinite(value) and low <= value <= high):
        raise PageValueError(control, value, f"within {low:g}..{high:g}{unit}")
    return float(value)
