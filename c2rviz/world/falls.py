"""Parts falling straight down on the world's clock, at g, one frame at a time.

``Falls`` belongs to a world's ``WorldParts``: ``start`` a part's fall of so many metres
onto something, and a timer on the clock lowers every falling part once per frame
(``z = z0 - g t² / 2``, never past where it lands), calls ``landed(part, onto)`` when it
gets there and ``stepped(done)`` after each frame (``done``: no part falls any more).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pinocchio as pin

from .clock import Clock, Timer
from .parts import Part

__all__ = ["G_M_S2", "Falls"]

G_M_S2 = 9.81
"""A falling part's acceleration [m/s²]."""


class Falls:
    """The parts falling now, and the frame timer that lowers them."""

    def __init__(
        self,
        clock: Clock,
        frame_s: float,
        landed: Callable[[Part, str], None],
        stepped: Callable[[bool], None],
    ) -> None:
        self.clock = clock
        self.frame_s = frame_s
        self.landed = landed
        self.stepped = stepped
        self._falls: dict[str, tuple[Part, float, float, float, str]] = {}
        self._timer: Timer | None = None

    def start(self, part: Part, down_m: float, onto: str) -> None:
        """``part`` falls ``down_m`` [m] from where it is now, onto ``onto``."""
        part.falling, part.on = True, None
        z0 = float(part.pose.translation[2])
        self._falls[part.name] = (part, self.clock.now(), z0, down_m, onto)
        if self._timer is None:
            self._timer = self.clock.call_later(self.frame_s, self._tick)

    def cancel(self, name: str) -> None:
        """Part ``name`` falls no more (taken, or removed)."""
        fall = self._falls.pop(name, None)
        if fall is not None:
            fall[0].falling = False

    def stop(self) -> None:
        """The program stops: no more frames."""
        if self._timer is not None:
            self._timer.cancel()
            self._timer = None

    def _tick(self) -> None:
        self._timer = None
        t = self.clock.now()
        for name, (part, t0, z0, down, onto) in list(self._falls.items()):
            fallen = min(down, 0.5 * G_M_S2 * (t - t0) ** 2)
            part.pose = pin.SE3(
                part.pose.rotation, np.array([*part.pose.translation[:2], z0 - fallen])
            )
            if fallen >= down:
                del self._falls[name]
                part.falling = False
                self.landed(part, onto)
        self.stepped(not self._falls)
        if self._falls:
            self._timer = self.clock.call_later(self.frame_s, self._tick)
