"""What the live page remembers of each robot: its last minutes, to plot and to look back at.

A ``RobotHistory`` keeps, for one robot of the world, at most one sample per
``period_s`` of the world's clock (the chain's values and the tool point, in the
robot's root frame [m]) for the last ``HISTORY_S``, and the changes of its
markers and workcell objects over the same time, so the page can draw the arm,
its markers and its objects as they were at any time of the window, and plot the
joints over any part of it.

Everything is bounded: at most ``MAX_SAMPLES`` samples (a sample per frame of a
100 Hz world for five minutes), ``MAX_MARKER_EVENTS`` marker changes and
``MAX_OBJECT_EVENTS`` object-list changes. A change past its bound folds the
oldest one into the state the window starts from, and the window then starts at
that change (``start``): a flood of ``mark`` shortens how far back one can look,
never the memory. A flood of joint values within a period keeps only the latest
(taken when the samples are read or the next period is due), as ``TrailKeeper``
does, so the history always ends where the arm is.

An arm at rest sends nothing, so the history is told when a sample leaves the arm at
rest (``add(..., resting=True)``): the next change, more than two periods later, is
kept as a step, the arm held where it rested until that time and then where it went
(two samples at one time), not as a ramp from the last sample. An instant move after
a minute at rest plots as a step.

The tool point of a sample (a forward kinematics) is worked out when a window is read,
not when the sample comes (most samples of most robots are never plotted): ``_append``
stores the chain's values, ``window`` computes the tool points it has not computed yet,
with the tool the robot had when each sample came (a change of tool first computes the
samples taken with the old one).
"""

from __future__ import annotations

import bisect
from collections import deque
from collections.abc import Sequence

import numpy as np
import pinocchio as pin

from ..collision.workcell import WorkcellObject
from ..world.state import MAX_MARKERS, Marker, RobotState

HISTORY_S = 300.0
"""How far back the live page can look [s of the world's clock]."""
MAX_SAMPLES = 30_000
"""Samples kept per robot at most (``HISTORY_S`` at 100 a second)."""
MAX_MARKER_EVENTS = 20_000
"""Marker changes (a mark, a clear) kept per robot; older ones fold into the start."""
MAX_OBJECT_EVENTS = 1_000
"""Workcell object-list changes kept per robot; older ones fold into the start."""


class Window:
    """Samples of a time span, oldest first (arrays the caller may keep).

    Attributes:
        times: Clock time of each sample [s], shape (k,).
        qs: The chain's values [rad or m], shape (k, n).
        tool: The tool point in the robot's root frame [m], shape (k, 3).
    """

    def __init__(self, times: np.ndarray, qs: np.ndarray, tool: np.ndarray) -> None:
        self.times = times
        self.qs = qs
        self.tool = tool

    def __len__(self) -> int:
        return len(self.times)


class RobotHistory:
    """One robot's last ``HISTORY_S``; see the module docstring.

    Attributes:
        period_s: Shortest time between two samples [s].
        folds: How many changes were folded into the start so far (a marker or object
            state read before a fold must be read again).
    """

    def __init__(
        self,
        state: RobotState,
        period_s: float,
        now: float,
        objects: Sequence[WorkcellObject],
        resting: bool = False,
    ) -> None:
        """Start remembering ``state``'s robot at clock time ``now`` [s], with the markers it
        has and ``objects`` (its workcell now); ``resting``: the arm is at rest now."""
        self.state = state
        self.period_s = max(period_s, HISTORY_S / MAX_SAMPLES)
        n = state.robot.n
        self._cap = MAX_SAMPLES
        size = self._cap + self._cap // 4  # room to append before the newest cap move down
        self._times = np.empty(size)
        self._qs = np.empty((size, n))
        self._tool = np.empty((size, 3))
        self._count = 0
        self._fk_count = 0  # samples whose tool point is computed (the oldest ones)
        self._fk_tool = state.tool  # the tool the samples from _fk_count on were taken with
        self._data = state.robot.model.createData()  # its own: computed between others' FKs
        self._due = -np.inf
        self._pending: tuple[tuple[float, ...], float] | None = None
        self._resting = False  # the arm stays at the latest state until the next one
        self.folds = 0
        self._start_s = now  # changes before this are folded into the base state
        self._base_markers: deque[Marker] = deque(state.markers, maxlen=MAX_MARKERS)
        self._marks: list[tuple[float, Marker | None]] = []  # None: a clear
        self._mark_times: list[float] = []
        self._base_objects: list[WorkcellObject] = list(objects)
        self._objects: list[tuple[float, list[WorkcellObject]]] = []
        self._object_times: list[float] = []
        self._cached: tuple[int, int, deque[Marker]] | None = None  # (folds, index, markers)
        self.add(state.q, now, resting)

    # what the world tells (the asyncio thread)

    def add(self, q: Sequence[float], t: float, resting: bool = False) -> None:
        """The arm is at ``q`` [rad or m] at clock time ``t`` [s]; ``resting``: it stays
        there until the next call (it arrived, or it moved at once)."""
        held, self._resting = self._resting, resting
        if t >= self._due:
            if held:  # at rest since the latest state: held there until now, then a step
                self._take_pending()
                last = self._count - 1
                if t - self._times[last] > 2.0 * self.period_s:
                    self._append(tuple(self._qs[last].tolist()), t)
            self._pending = None
            self._append(tuple(q), t)
            self._due = t + self.period_s
        else:
            self._pending = (tuple(q), t)

    def mark(self, marker: Marker, t: float) -> None:
        """One more marker at clock time ``t``."""
        self._event(self._marks, self._mark_times, (t, marker), MAX_MARKER_EVENTS)

    def clear(self, t: float) -> None:
        """Every marker gone at clock time ``t``."""
        self._event(self._marks, self._mark_times, (t, None), MAX_MARKER_EVENTS)

    def objects(self, objects: Sequence[WorkcellObject], t: float) -> None:
        """The workcell is ``objects`` from clock time ``t`` on."""
        entry = (t, list(objects))
        self._event(self._objects, self._object_times, entry, MAX_OBJECT_EVENTS)

    # what the page reads

    @property
    def start(self) -> float:
        """The earliest time the history can show [s] (everything after it is known)."""
        self._take_pending()
        oldest = float(self._times[0]) if self._count else self._start_s
        return max(oldest, self._start_s, self.end - HISTORY_S)

    @property
    def end(self) -> float:
        """The time of the latest sample [s]."""
        self._take_pending()
        return float(self._times[self._count - 1]) if self._count else self._start_s

    def window(self, t0: float, t1: float) -> Window:
        """The samples from ``t0`` to ``t1`` [s] (and the one before ``t0``, so a line starts
        at the window's edge); copies."""
        self._take_pending()
        times = self._times[: self._count]
        lo = max(int(np.searchsorted(times, t0, side="right")) - 1, 0)
        lo = max(lo, int(np.searchsorted(times, self.start, side="left")))
        hi = int(np.searchsorted(times, t1, side="right"))
        self._compute_tool(hi)
        return Window(times[lo:hi].copy(), self._qs[lo:hi].copy(), self._tool[lo:hi].copy())

    def at(self, t: float) -> tuple[float, ...]:
        """The chain's values [rad or m] at time ``t`` [s]: the latest sample at or before it
        (the oldest one kept, before the start)."""
        self._take_pending()
        k = int(np.searchsorted(self._times[: self._count], t, side="right")) - 1
        return tuple(self._qs[max(k, 0)].tolist())

    def markers_at(self, t: float) -> tuple[tuple[int, int], deque[Marker]]:
        """The markers as they were at time ``t`` [s], oldest first, and a key that changes
        whenever they may differ from an earlier answer (so a page redraws only then)."""
        index = bisect.bisect_right(self._mark_times, t)
        cached = self._cached
        if cached is not None and cached[0] == self.folds and cached[1] <= index:
            markers, done = cached[2], cached[1]
        else:
            markers, done = deque(self._base_markers, maxlen=MAX_MARKERS), 0
        for _, marker in self._marks[done:index]:
            if marker is None:
                markers.clear()
            else:
                markers.append(marker)
        self._cached = (self.folds, index, markers)
        return (self.folds, index), markers

    def objects_at(self, t: float) -> list[WorkcellObject]:
        """The workcell objects as they were at time ``t`` [s]."""
        index = bisect.bisect_right(self._object_times, t)
        return self._objects[index - 1][1] if index else self._base_objects

    # keeping it bounded

    def _append(self, q: tuple[float, ...], t: float) -> None:
        if self._count == len(self._times):  # keep the newest cap, contiguous, at the front
            keep = slice(self._count - self._cap, self._count)
            self._times[: self._cap] = self._times[keep]
            self._qs[: self._cap] = self._qs[keep]
            self._tool[: self._cap] = self._tool[keep]
            self._fk_count = max(self._fk_count - (self._count - self._cap), 0)
            self._count = self._cap
        if self.state.tool is not self._fk_tool:  # the samples so far keep the old tool
            self._compute_tool(self._count)
            self._fk_tool = self.state.tool
        k = self._count
        self._times[k] = t
        self._qs[k] = q
        self._count = k + 1
        self._fold_older(t - HISTORY_S)

    def _compute_tool(self, count: int) -> None:
        """Compute the tool points of the first ``count`` samples that are not yet: one
        Pinocchio FK each, the tool point placed from the end effector's parent joint
        (``oMi * (frame placement * tool)``, the tool's offset worked out once)."""
        if count <= self._fk_count:
            return
        robot = self.state.robot
        model, data = robot.model, self._data
        frame = model.frames[robot.ee_frame]
        joint, offset = frame.parentJoint, (frame.placement * self._fk_tool).translation
        for k in range(self._fk_count, count):
            pin.forwardKinematics(model, data, robot.configuration(self._qs[k]))
            self._tool[k] = data.oMi[joint].act(offset)
        self._fk_count = count

    def _take_pending(self) -> None:
        if self._pending is not None:
            (q, t), self._pending = self._pending, None
            self._append(q, t)

    def _event(self, events: list, times: list[float], entry: tuple, cap: int) -> None:
        events.append(entry)
        times.append(entry[0])
        if len(events) > cap:
            self._fold(events, times, len(events) - cap)
        self._fold_older(entry[0] - HISTORY_S)

    def _fold_older(self, before: float) -> None:
        """Fold the changes older than ``before`` [s] into the base state."""
        for events, times in ((self._marks, self._mark_times), (self._objects, self._object_times)):
            count = bisect.bisect_left(times, before)
            if count:
                self._fold(events, times, count)

    def _fold(self, events: list, times: list[float], count: int) -> None:
        """The ``count`` oldest changes of ``events`` become part of the base state."""
        if events is self._marks:
            for _, marker in events[:count]:
                if marker is None:
                    self._base_markers.clear()
                else:
                    self._base_markers.append(marker)
        else:
            self._base_objects = events[count - 1][1]
        self._start_s = max(self._start_s, times[count - 1])
        del events[:count]
        del times[:count]
        self.folds += 1
