"""Live plots in a robot's folder: its joints over the last seconds, their velocities, the
tool point's speed (uPlot charts through viser's ``add_uplot``).

A ``RobotPlots`` draws from the robot's ``RobotHistory``: the window of the last
``Window s`` seconds (5 to 120) before the time the page shows (now, or the
timeline's time when looking back: the plots end there), thinned to at most
``PLOT_POINTS`` points per line, which is about what a chart in the side panel
can show. Joint values are in the page's units: degrees for revolute joints,
metres for prismatic ones; each plotted joint's limits are dashed lines of its
colour (none for a continuous joint). The joints plotted are chosen by checkbox;
``Pause plots`` freezes the charts (not the robot); ``Velocities`` shows the
velocity chart (on by default when moves take time).

Plots cost the server a chart update (three arrays per joint) per draw, so the
page draws them at most ``PLOT_HZ`` a second, and at most ``PLOTS_PER_S`` a
second over all robots; a change after a quiet spell goes out with the frame
that shows it (``due``). The charts are the page's, like
every control: all tabs show the same ones, and a late tab is sent their state.
"""

from __future__ import annotations

import html
import math
from typing import Any

import numpy as np
import viser
import viser.uplot as uplot

from ..robot.model import Robot
from . import adapter
from .history import RobotHistory
from .panel import short_label
from .timeline import within

WINDOW_RANGE_S = (5.0, 120.0)
"""Shortest and longest plot window [s]."""
DEFAULT_WINDOW_S = 20.0
PLOT_POINTS = 200
"""Points per line at most (a chart in the side panel is about 300 pixels wide)."""
PLOT_HZ = 10.0
"""Chart updates a second at most, per robot."""
PLOTS_PER_S = 80.0
"""Chart updates a second at most, all robots together: in a cell of more than
``PLOTS_PER_S / PLOT_HZ`` robots each robot's charts go out less often (64 robots: every
0.8 s), which bounds what the plots cost the server and the page."""
COLORS = ("#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf")
_X = uplot.Series(label="t [s]")
_SCALES = {"x": uplot.Scale(time=False)}


def legend(robot: Robot) -> str:
    """The charts' key: each joint's name in its colour (markdown; the names escaped)."""
    keys = " ".join(
        f'<span style="color:{COLORS[i % len(COLORS)]}">&#9473;&nbsp;{html.escape(j.name)}</span>'
        for i, j in enumerate(robot.joints)
    )
    return f"{keys} <span style='color:#888'>(dashed: its limits)</span>"


def thin(count: int, points: int = PLOT_POINTS, times: np.ndarray | None = None) -> np.ndarray:
    """Indices of at most ``points`` samples of ``count``, evenly spread, first and last
    kept. With the samples' ``times`` [s], the corners of each long pause (more than two
    thinned steps without a sample: the arm at rest) are kept too, at most ``points // 2``
    of them, so a step after a rest stays a step (``history``) rather than a ramp across
    the pause."""
    if count <= points:
        return np.arange(count)
    corners = np.zeros(0, dtype=int)
    if times is not None and count > 1:
        pauses = np.flatnonzero(np.diff(times) > 2.0 * (times[-1] - times[0]) / points)
        ends = np.concatenate([pauses, pauses + 1, np.minimum(pauses + 2, count - 1)])
        corners = np.unique(ends)[: points // 2]
    even = np.linspace(0, count - 1, points - len(corners)).round().astype(int)
    return np.unique(np.concatenate([even, corners]))


class RobotPlots:
    """One robot's charts and their controls; see the module docstring.

    Attributes:
        shown: The ``Plots`` checkbox (no chart updates while it is off).
        window: The ``Window s`` slider [s].
        pause: The ``Pause plots`` checkbox.
        velocities: The ``Velocities`` checkbox.
        joints: A checkbox per joint of the chain: plotted or not.
        legend: Each joint's colour (the charts draw no legend of their own).
        positions: The joint chart [deg or m].
        speeds: The velocity chart [deg/s or m/s].
        tool_speed: The tool point's speed chart [m/s].
        period_s: Shortest time between two updates [s of real time].
        drawn_s: The time the charts last ended at [s of the clock], None before the first.
        draws: Chart updates so far.
    """

    def __init__(
        self,
        gui: viser.GuiApi,
        robot: Robot,
        origin_s: float,
        velocities: bool,
        robots: int = 1,
        order: float | None = None,
    ) -> None:
        """Add the charts to the folder open in ``gui``; times are plotted in seconds from
        ``origin_s`` (the server's start, as ``watch``) [s of the clock]; ``robots`` is how
        many robots' charts share ``PLOTS_PER_S``; ``order``: where the ``Plots`` folder
        stands among the folder's rows (viser's order; None: last)."""
        self.robot = robot
        self.period_s = max(1.0 / PLOT_HZ, robots / PLOTS_PER_S)
        self.origin_s = origin_s
        self._scale = np.array([1.0 if j.prismatic else 180.0 / math.pi for j in robot.joints])
        self._units = ["m" if j.prismatic else "deg" for j in robot.joints]
        with gui.add_folder("Plots", expand_by_default=True, order=order):
            # the charts first, their controls under them: a 900 px screen shows them
            self.legend: Any = gui.add_markdown(legend(robot))
            empty = (np.zeros(1), *(np.zeros(1) for _ in robot.joints))
            self.positions: Any = gui.add_uplot(
                empty,
                (_X, *self._joint_series(range(robot.n))),
                title=f"joints [{self._unit_text()}]",
                scales=_SCALES,
                legend=uplot.Legend(show=False),  # the colours are in ``legend``, once
                aspect=1.6,
            )
            self.speeds: Any = gui.add_uplot(
                empty,
                (_X, *self._joint_series(range(robot.n))),
                title=f"velocities [{self._unit_text()}/s]",
                scales=_SCALES,
                legend=uplot.Legend(show=False),
                aspect=1.8,
                visible=velocities,
            )
            self.tool_speed: Any = gui.add_uplot(
                (np.zeros(1), np.zeros(1)),
                (_X, uplot.Series(label="tool m/s", stroke="#444444", width=1.5)),
                title="tool point speed [m/s]",
                scales=_SCALES,
                legend=uplot.Legend(show=False),
                aspect=2.4,
            )
            self.shown: Any = gui.add_checkbox(
                "Plots", True, hint="update the charts (off: they cost the server nothing)"
            )
            low, high = WINDOW_RANGE_S
            self.window: Any = gui.add_slider(
                "Window s",
                min=low,
                max=high,
                step=1.0,
                initial_value=DEFAULT_WINDOW_S,
                hint=f"seconds plotted, {low:g} to {high:g}, up to the time shown",
            )
            self.pause: Any = gui.add_checkbox(
                "Pause plots", False, hint="freeze the charts (the robot goes on)"
            )
            self.velocities: Any = gui.add_checkbox(
                "Velocities", velocities, hint="show the joints' velocities"
            )
            with gui.add_folder("Joints plotted", expand_by_default=False):
                self.joints = [
                    gui.add_checkbox(short_label(j.name), True, hint=f"plot {j.name}")
                    for j in robot.joints
                ]
        self._chosen: tuple[int, ...] | None = None  # the series are set at the first draw
        self._limits: tuple[tuple[tuple[int, ...], int], list[np.ndarray]] | None = None
        self._last_draw = -math.inf
        self.drawn_s: float | None = None
        self.draws = 0

    # what the page's controls set (values already screened by the door)

    def set_window(self, seconds: float) -> float:
        """The window is ``seconds`` long from now on.

        Raises:
            PageValueError: outside ``WINDOW_RANGE_S``.
        """
        return within("plot window", seconds, *WINDOW_RANGE_S, " s")

    def chosen(self) -> tuple[int, ...]:
        """The joints plotted, by index."""
        return tuple(i for i, box in enumerate(self.joints) if box.value)

    # drawing

    def due(self, now_s: float) -> bool:
        """Whether a draw may go out now (``period_s``), if the charts are on and not paused.

        ``now_s`` is real time [s] (the loop's), which bounds the server's cost."""
        if not self.shown.value or self.pause.value:
            return False
        return now_s - self._last_draw >= self.period_s

    def wait_s(self, now_s: float) -> float:
        """How long until a draw may go out [s of real time]."""
        return max(self._last_draw + self.period_s - now_s, 0.0)

    def draw(self, history: RobotHistory, end_s: float, now_s: float) -> None:
        """Update the charts to the window ending at clock time ``end_s`` [s]."""
        self._last_draw = now_s
        self.draws += 1
        self.drawn_s = end_s
        window = history.window(end_s - float(self.window.value), end_s)
        picked = thin(len(window), PLOT_POINTS, window.times)
        times = window.times[picked]
        x = times - self.origin_s
        chosen = self.chosen()
        if chosen != self._chosen:
            self._chosen = chosen
            bounded = [i for i in chosen if not self.robot.joints[i].continuous]
            self.positions.series = (_X, *self._joint_series(chosen), *self._limit_series(bounded))
            self.speeds.series = (_X, *self._joint_series(chosen))
        columns = list(chosen)
        previous = np.maximum(picked - 1, 0)
        dt = window.times[picked] - window.times[previous]
        dt[dt <= 0.0] = np.inf  # the first sample, or a step (two at one time): show 0
        if columns:
            values = window.qs[picked][:, columns] * self._scale[columns]
            limits = self._limit_values(chosen, len(x))
            adapter.set_chart_data(self.positions, (x, *values.T, *limits))
            if self.velocities.value:
                rates = (window.qs[picked] - window.qs[previous])[:, columns] / dt[:, None]
                adapter.set_chart_data(self.speeds, (x, *(rates * self._scale[columns]).T))
        _show(self.positions, bool(columns))
        _show(self.speeds, bool(self.velocities.value) and bool(columns))
        moved = np.linalg.norm(window.tool[picked] - window.tool[previous], axis=1)
        adapter.set_chart_data(self.tool_speed, (x, moved / dt))

    def _unit_text(self) -> str:
        return "/".join(sorted(set(self._units), key=self._units.index))

    def _joint_series(self, indices: Any) -> list[uplot.Series]:
        joints = self.robot.joints
        return [
            uplot.Series(
                label=short_label(joints[i].name, 8),
                stroke=COLORS[i % len(COLORS)],
                width=1.5,
            )
            for i in indices
        ]

    def _limit_series(self, indices: list[int]) -> list[uplot.Series]:
        joints = self.robot.joints
        return [
            uplot.Series(
                label=f"{short_label(joints[i].name, 6)} {end}",
                stroke=COLORS[i % len(COLORS)],
                width=1.0,
                dash=(4.0, 4.0),
                alpha=0.6,
            )
            for i in indices
            for end in ("min", "max")
        ]

    def _limit_values(self, chosen: tuple[int, ...], count: int) -> list[np.ndarray]:
        """The dashed limit lines' values, ``count`` points each (kept while the joints
        chosen and the count stay the same; never changed once sent)."""
        key = (chosen, count)
        if self._limits is not None and self._limits[0] == key:
            return self._limits[1]
        out = []
        for i in chosen:
            joint = self.robot.joints[i]
            if joint.continuous:
                continue
            for value in (joint.lower, joint.upper):
                out.append(np.full(count, value * self._scale[i]))
        self._limits = (key, out)
        return out


def _show(chart: Any, visible: bool) -> None:
    """``chart.visible = visible``, without viser's cast when it is already so."""
    if chart.visible != visible:
        chart.visible = visible
