"""The page's side panel: a folder per robot with its readout, and the program's state
below them.

Each robot's folder (headed by its name in the world) holds a slider per
joint (degrees, metres for a prismatic joint), a speed slider for the page's
own moves, Home / Random / Stop buttons, the end effector's pose and the
motion status, Trail and Ghost checkboxes, the colliding pairs, and the marker last
clicked in the scene with a "Go to marker" button. The ``State`` folder
shows the TCP client count and the last commands, newest first, a refused
one marked so; a checkbox shows the collision geometry.

Controls only show values here: what the page does with them is
``page_input``'s. Values go out with ``adapter.set_gui_value`` (no callbacks,
only on change); ``force`` sends the true value back to a tab that shows
another one (a refused page value).

The readout (``RobotReadout``) is a small table in a robot's folder with what it is doing,
updated live. It shows each joint's value (degrees, metres for a prismatic joint), the
tool point's pose in the base frame, the motion state (``idle``, ``moving 1.2 s left``)
and the robot's last error (the line and why it was refused, from any source). While the
page looks back, the joints and the tool pose are those of the time shown, and the table
says which time that is. It is redrawn at most ``READOUT_HZ`` a second (and at most
``READOUTS_PER_S`` a second over all the robots of a cell) and only when its text changes.

Text from a client (a refused line) is escaped: the table is markdown, and a
line must show as the characters it is, never as markup.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Iterable, Sequence
from typing import Any

import numpy as np
import pinocchio as pin
import viser

from ..errors import limit_text
from ..robot.frames import se3_pose
from ..robot.model import Robot
from ..world.state import Marker, RobotState
from . import adapter

RECENT_COMMANDS = 8  # lines kept for the 'last commands' readout
SHOWN_LINE_CHARS = 80
MAX_LABEL_CHARS = 13  # what fits on one line beside a slider in a folder
REJECTED = "  [rejected]"
NO_MARKER = "click one in the scene"
_AFFIXES = ("_joint", "joint_", "_jnt")


def short_label(name: str, limit: int = MAX_LABEL_CHARS) -> str:
    """``name`` short enough for one line of a slider label (the hint keeps it whole)."""
    if len(name) <= limit:
        return name
    for affix in _AFFIXES:
        name = name.removesuffix(affix) if affix.startswith("_") else name.removeprefix(affix)
    return name if len(name) <= limit else name[: limit - 1] + "…"


class RobotPanel:
    """One robot's folder; see the module docstring.

    Attributes:
        name: The robot's name in the world (the folder's heading).
        sliders: A slider per joint of the chain, in chain order.
        speed: The page's speed slider [% of the limits].
        buttons: ``home``, ``rand`` and ``stop``, by the line each runs.
        pose: The end-effector readout (in the base frame).
        motion: ``idle`` or ``moving, 1.20 s left``.
        trail: The Trail checkbox (runs ``trail on`` / ``trail off``).
        ghost: The Ghost checkbox (runs ``ghost on`` / ``ghost off``).
        folder: The folder (the plots and the readout are added to it).
        collisions: The colliding pairs readout.
        marker: The readout of the marker clicked last (``chosen``).
        goto: The "Go to marker" button (runs ``moveto marker N``).
        chosen: The marker clicked last, until it is gone.
        banner: The fault banner atop the folder (``fault``: a stop, or the faults on).
    """

    def __init__(self, gui: viser.GuiApi, state: RobotState, speed: float) -> None:
        robot = state.robot
        self.name = state.name
        self.robot = robot
        self.ranges: list[tuple[float, float]] = []
        self.sliders: list[Any] = []
        self.folder: Any = gui.add_folder(state.name)
        with self.folder:
            self.banner: Any = gui.add_markdown("", visible=False)  # a fault, when there is one
            for i, joint in enumerate(robot.joints):
                if joint.prismatic:
                    low, high, step, unit = joint.lower, joint.upper, 0.001, "m"
                elif joint.continuous:
                    low, high, step, unit = -180.0, 180.0, 0.1, "deg"
                else:
                    low, high = math.degrees(joint.lower), math.degrees(joint.upper)
                    step, unit = 0.1, "deg"
                # The slider stops at its last step inside each limit (it cannot pass one)
                # and its end labels say where; the hint gives the limits as `limits` and
                # errors print them (printed under the track, 10 digits do not fit).
                ends = (limit_text(low), limit_text(high))
                low = round(math.ceil(low / step - 1e-9) * step, 6)
                high = round(math.floor(high / step + 1e-9) * step, 6)
                self.ranges.append((low, high))
                self.sliders.append(
                    gui.add_slider(
                        short_label(joint.name),
                        min=low,
                        max=high,
                        step=step,
                        initial_value=self.to_slider(i, state.target[i]),
                        hint=f"joint {i}: {joint.name} [{unit}], "
                        + ("turns freely" if joint.continuous else f"limits {ends[0]}..{ends[1]}"),
                    )
                )
            self.speed: Any = gui.add_slider(
                "Speed %",
                min=1.0,
                max=100.0,
                step=1.0,
                initial_value=speed,
                hint="speed of the page's own moves, % of the joints' limits",
            )
            self.buttons = {
                "home": gui.add_button(
                    "Home", hint="every joint home: 0, or its nearest limit if 0 is outside"
                ),
                "rand": gui.add_button("Random", hint="every joint to a random value"),
                "stop": gui.add_button("Stop", hint="stop the arm where it is"),
            }
            # Typed Any: mypy reads viser's GuiTextHandle.value as read-only, though it is not.
            self.pose: Any = gui.add_text(
                "End effector",
                "",
                multiline=True,
                disabled=True,
                hint=f"{robot.eelink} in the {robot.base} frame",
            )
            self.motion: Any = gui.add_text("Motion", "idle", disabled=True)
            self.trail: Any = gui.add_checkbox(
                "Trail", False, hint="draw the end effector's path (trail on / trail off)"
            )
            self.ghost: Any = gui.add_checkbox(
                "Ghost",
                state.ghost,
                hint="while it travels: the target as a ghost, a movel or planned path as a "
                "line (ghost on / ghost off)",
            )
            self.collisions: Any = gui.add_text(
                "Collisions", "none", disabled=True, hint="colliding pairs, link~object"
            )
            self.marker: Any = gui.add_text(
                "Marker", NO_MARKER, disabled=True, hint="the marker clicked last (world frame)"
            )
            self.goto: Any = gui.add_button(
                "Go to marker",
                disabled=True,
                hint="move the tool to the marker clicked last (moveto marker N)",
            )
        self.chosen: Marker | None = None
        self._shown_target: tuple[float, ...] | None = None  # every slider shows it
        self._shown_motion: tuple[bool, float] | None = None

    def to_slider(self, index: int, value: float) -> float:
        """Joint value [rad or m] in slider units (deg or m), within the slider's range."""
        joint = self.robot.joints[index]
        shown = float(value) if joint.prismatic else math.degrees(value)
        if joint.continuous:
            shown = (shown + 180.0) % 360.0 - 180.0
        if index < len(self.ranges):
            low, high = self.ranges[index]
            shown = min(max(shown, low), high)
        return round(shown, 6)  # 30, not 29.999999999999996 (which the page shows as "30.0")

    def show_joints(self, target: Sequence[float], busy: Callable[[Any], bool]) -> None:
        """Every slider to the commanded value, but those the page is moving (``busy``).

        A target every slider shows already costs one comparison (a send of many robots
        asks for each robot's sliders at each frame; the target changes with a command)."""
        target = tuple(target)
        if target == self._shown_target:
            return
        skipped = False
        for i, (slider, value) in enumerate(zip(self.sliders, target)):
            if busy(slider):
                skipped = True
            else:
                adapter.set_gui_value(slider, self.to_slider(i, value))
        self._shown_target = None if skipped else target

    def answer(self, index: int, sent: float, value: float, client: int, force: bool) -> None:
        """After the page set slider ``index`` to ``sent``: show the true ``value`` [rad or
        m] on every tab; the tab that sent it is skipped if it already shows it."""
        shown = self.to_slider(index, value)
        self._shown_target = None  # show_joints looks at every slider again
        if shown == sent and not force:
            adapter.set_gui_value(self.sliders[index], shown, exclude_client=client)
        else:
            adapter.set_gui_value(self.sliders[index], shown, force=True)

    def show_pose(self, ee: pin.SE3) -> None:
        """The end effector's placement in the base frame, in mm-rounded metres and degrees."""
        # round() then + 0.0: no "-0.0" in the readout
        x, y, z = (round(float(v), 3) + 0.0 for v in ee.translation)
        roll, pitch, yaw = (round(float(v), 1) + 0.0 for v in np.degrees(se3_pose(ee)[3:]))
        text = f"x {x:+.3f}  y {y:+.3f}  z {z:+.3f} m\n"
        text += f"R {roll:+.1f}  P {pitch:+.1f}  Y {yaw:+.1f} deg"
        adapter.set_gui_value(self.pose, text)

    def show_motion(self, moving: bool, seconds_left: float) -> None:
        """``idle``, or ``moving, 1.2 s left`` (``seconds_left`` [s])."""
        if (moving, seconds_left) == self._shown_motion:
            return
        self._shown_motion = (moving, seconds_left)
        text = f"moving, {seconds_left:.1f} s left" if moving else "idle"
        adapter.set_gui_value(self.motion, text)

    def show_collisions(self, pairs: Sequence[tuple[str, str]]) -> None:
        """The colliding pairs, ``a~b, c~d``; ``none`` when there are none."""
        self.collisions.value = ", ".join(f"{a}~{b}" for a, b in pairs) or "none"

    def choose(self, marker: Marker | None) -> None:
        """``marker`` is the one clicked last (None: none, or it is gone)."""
        self.chosen = marker
        self.goto.disabled = marker is None
        if marker is None:
            self.marker.value = NO_MARKER
        else:
            x, y, z = (round(float(v), 3) + 0.0 for v in marker.position)
            self.marker.value = f"x {x:+.3f}  y {y:+.3f}  z {z:+.3f} m"

    def show_faults(self, text: str) -> None:
        """The fault banner says ``text`` (markdown); hidden when it is empty."""
        if text:
            self.banner.content = text
        self.banner.visible = bool(text)

    def show_trail(self, on: bool) -> None:
        """The Trail checkbox to ``on`` (set by a ``trail`` line from anywhere)."""
        adapter.set_gui_value(self.trail, on)

    def show_ghost(self, on: bool) -> None:
        """The Ghost checkbox to ``on`` (set by a ``ghost`` line from anywhere)."""
        adapter.set_gui_value(self.ghost, on)


class StatePanel:
    """The program's state: TCP clients, last commands, the collision checkbox."""

    def __init__(self, gui: viser.GuiApi) -> None:
        self.collision: Any = gui.add_checkbox(
            "Collision", False, hint="show each link's collision geometry"
        )
        with gui.add_folder("State"):
            self.clients: Any = gui.add_text("TCP clients", "0", disabled=True)
            self.recent: Any = gui.add_text(
                "Last commands",
                "",
                multiline=True,
                disabled=True,
                hint=f"the last {RECENT_COMMANDS}, newest first",
            )

    def show(self, clients: int, commands: Iterable[tuple[str, bool]]) -> None:
        """``clients`` TCP clients; ``commands`` (line, accepted), newest first."""
        self.clients.value = str(clients)
        self.recent.value = "\n".join(
            _shown(line) + ("" if accepted else REJECTED) for line, accepted in commands
        )


def _shown(line: str) -> str:
    line = line.replace("\r", " ").replace("\t", " ").replace("\n", " ")
    return line if len(line) <= SHOWN_LINE_CHARS else line[: SHOWN_LINE_CHARS - 3] + "..."


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
