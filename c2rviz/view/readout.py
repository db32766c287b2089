"""The readout: a small table in a robot's folder with what it is doing, updated live.

It shows each joint's value (degrees, metres for a prismatic joint), the tool
point's pose in the base frame, the motion state (``idle``, ``moving 1.2 s
left``) and the robot's last error (the line and why it was refused, from any
source). While the page looks back, the joints and the tool pose are those of
the time shown, and the table says which time that is. It is redrawn at most
``READOUT_HZ`` a second (and at most ``READOUTS_PER_S`` a second over all the
robots of a cell) and only when its text changes.

Text from a client (a refused line) is escaped: the table is markdown, and a
line must show as the characters it is, never as markup.
"""

from __future__ import annotations

import math
import re
from collections.abc import Sequence
from typing import Any

import numpy as np
import pinocchio as pin
import viser

from ..robot.model import Robot

__all__ = ["READOUTS_PER_S", "READOUT_HZ", "RobotReadout", "escape"]

READOUT_HZ = 10.0
"""Readout updates a second at most, per robot."""
READOUTS_PER_S = 160.0
"""Readout updates a second at most, all robots together (64 robots: 2.5 a second each)."""
SHOWN_CHARS = 80
_MARKUP = re.compile(r"([\\`*_{}\[\]()#+\-.!|~>])")


def escape(text: str, limit: int = SHOWN_CHARS) -> str:
    """``text`` as literal characters in markdown: one line, cut at ``limit``, no markup."""
    text = " ".join(text.split())
    if len(text) > limit:
        text = text[: limit - 3] + "..."
    text = text.replace("&", "&amp;").replace("<", "&lt;")
    return _MARKUP.sub(r"\\\1", text)


class RobotReadout:
    """One robot's table; see the module docstring.

    Attributes:
        table: The markdown element.
        error: The last error shown (``line: message``), or None.
        period_s: Shortest time between two updates [s of real time].
        updates: Times the table's text was sent.
    """

    def __init__(self, gui: viser.GuiApi, robot: Robot, robots: int = 1) -> None:
        """Add the table to the folder open in ``gui``; ``robots`` is how many robots'
        readouts share ``READOUTS_PER_S``."""
        self.robot = robot
        self.period_s = max(1.0 / READOUT_HZ, robots / READOUTS_PER_S)
        self._names = [escape(joint.name, 24) for joint in robot.joints]
        self.table: Any = gui.add_markdown("")
        self.error: str | None = None
        self.updates = 0
        self._last_s = -math.inf
        self._text = ""

    def refused(self, line: str, message: str) -> None:
        """The robot's last error is now ``line`` refused with ``message``."""
        self.error = f"{escape(line, 40)}: {escape(message)}"

    def due(self, now_s: float) -> bool:
        """Whether an update may go out now [s of real time]."""
        return now_s - self._last_s >= self.period_s

    def wait_s(self, now_s: float) -> float:
        """How long until an update may go out [s of real time]."""
        return max(self._last_s + self.period_s - now_s, 0.0)

    def show(
        self,
        q: Sequence[float],
        tool: pin.SE3,
        motion: str,
        at: str | None,
        now_s: float,
    ) -> None:
        """Show chain values ``q`` [rad or m], the tool point's placement ``tool`` (base
        frame), the ``motion`` state, and ``at`` (the time shown when looking back)."""
        self._last_s = now_s
        rows = ["| | |", "|:--|--:|"]
        if at is not None:
            rows.append(f"| **at** | {at} |")
        for joint, name, value in zip(self.robot.joints, self._names, q):
            shown = f"{value:.4f} m" if joint.prismatic else f"{math.degrees(value):.2f}°"
            rows.append(f"| {name} | {shown} |")
        x, y, z = (round(float(v), 4) + 0.0 for v in tool.translation)
        roll, pitch, yaw = (
            round(float(v), 2) + 0.0 for v in np.degrees(pin.rpy.matrixToRpy(tool.rotation))
        )
        rows.append(f"| tool xyz | {x:+.4f} {y:+.4f} {z:+.4f} m |")
        rows.append(f"| tool rpy | {roll:+.2f} {pitch:+.2f} {yaw:+.2f}° |")
        rows.append(f"| motion | {motion} |")
        rows.append(f"| last error | {self.error or 'none'} |")
        text = "\n".join(rows)
        if text != self._text:
            self._text = text
            self.table.content = text
            self.updates += 1

    @property
    def text(self) -> str:
        """The table's markdown as last sent."""
        return self._text
