"""Faults in a recording's command file: the lines that put them on in a replay.

``Recorder`` writes each fault's line at its time (``fault_line``: the world's
``replay_line``), after the frames it caused. Two kinds of line are not a fault event's
own:

- **At the start**, the faults already on (``opening_lines``): each lasting fault's
  ``fault KIND ARGS`` (an estop cleared but not yet reset as ``fault estop`` then ``fault
  clear estop``, so the replay too waits for ``reset``) and each camera's blackout for
  the time it has left. The recorder writes them after the first frame, so a stalled
  joint holds where the arm is. Scheduled faults are not written ahead: each is written
  when it begins, as every fault is. ``latency`` and ``disconnect`` are never written
  (they would act on the replaying client itself).
- **Slips**: a replay must make the grasps the run made, not draw on chance again. So
  ``fault slip P`` is written as a comment, and before each grasp that drew
  (``slip_outcome``) ``fault slip 1`` (it slipped) or ``fault slip 0`` (it held), when
  it differs from the last one written: the replay's draws meet a certainty.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

from ..world.cameras import Camera
from ..world.faults import RobotFaults, at_once, replay_line

__all__ = ["HELD", "SLIPPED", "FaultLines", "fault_line", "opening_lines", "slip_outcome"]

SLIPPED = "fault slip 1"
"""Written before a grasp that slipped: the replay's draw cannot hold."""
HELD = "fault slip 0"
"""Written before a grasp that held: the replay's draw cannot slip."""


def fault_line(text: str) -> str | None:
    """The line that replays the fault event ``text`` (None: none), ``fault slip P`` as a
    comment (each grasp's outcome is written instead)."""
    line = replay_line(text)
    if line is not None and line.startswith("fault slip "):
        return f"# {line} (each grasp's draw follows: {SLIPPED} slipped, {HELD} held)"
    return line


def slip_outcome(faults: RobotFaults, event: str) -> str | None:
    """The outcome line of the grasp a part event tells (``slipped NAME``: it slipped;
    ``grasped NAME`` with a slip fault on: it drew and held), None for any other event."""
    if event.startswith("slipped "):
        return SLIPPED
    if event.startswith("grasped ") and "slip" in faults.active:
        return HELD
    return None


def opening_lines(
    faults: RobotFaults, cameras: Sequence[Camera], now: float, joint_names: tuple[str, ...]
) -> list[str]:
    """The lines that put on, in a replay, the faults on at clock time ``now`` [s]: those of
    ``faults`` (a robot's) and the blackouts of ``cameras``."""
    lines = []
    for fault, _ in faults.active.values():
        line = fault_line(f"fault {fault.text(joint_names)}")
        if line is not None:
            lines.append(line)
    latch = faults.latch
    if latch is not None and latch.kind == "estop" and latch.released:
        lines += ["fault estop", "fault clear estop"]
    for camera in cameras:
        if camera.dark(now):
            left = camera.blackout_until - now
            timed = f" {left!r}" if math.isfinite(left) else ""
            lines.append(f"fault blackout {camera.name}{timed}")
    return lines


@dataclass
class FaultLines:
    """One recording's fault lines: those waiting for the arm to rest, and the last grasp
    outcome written (``slip``)."""

    waiting: list[str] = field(default_factory=list)
    slip: str | None = None

    def add(self, text: str, moving: bool) -> bool:
        """Keep the line of the fault event ``text``, if it has one; True: write the
        waiting lines now (the arm rests, or it is a line written at once: a drop)."""
        line = fault_line(text)
        if line is None:
            return False
        if "slip" in line:  # a slip begins or ends: the next grasp's outcome is written
            self.slip = None
        self.waiting.append(line)
        return not moving or (self.waiting == [line] and at_once(line))

    def take(self) -> list[str]:
        """The waiting lines, to write now."""
        lines, self.waiting = self.waiting, []
        return lines

    def outcome(self, faults: RobotFaults, event: str) -> str | None:
        """The outcome line to write before the grasp the part event ``event`` tells (None:
        no draw, or the same outcome as the last one written)."""
        line = slip_outcome(faults, event)
        if line is None or line == self.slip:
            return None
        self.slip = line
        return line
