"""The live page's memory (``view.history``): what it keeps, for how long, and within what."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from support import load_robot

from c2rviz.collision.workcell import WorkcellObject
from c2rviz.view.history import HISTORY_S, MAX_MARKER_EVENTS, MAX_SAMPLES, RobotHistory
from c2rviz.view.plots import thin
from c2rviz.world.state import Marker, RobotState


def history(now: float = 0.0) -> RobotHistory:
    return RobotHistory(RobotState("arm", load_robot()), 0.01, now, [])


def marker(x: float) -> Marker:
    return Marker((x, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0), (1.0, 0.0, 0.0), "sphere")


def test_samples_come_at_most_once_a_period_and_the_latest_state_wins() -> None:
    h = history()
    for k in range(1, 1001):  # a flood within one period: only the last is kept
        h.add((k * 1e-4,) * 7, 0.005)
    h.add((0.5,) * 7, 0.02)
    h.add((0.6,) * 7, 0.021)  # pending: the history still ends at it
    window = h.window(-1.0, 1.0)
    assert list(window.times) == [0.0, 0.02, 0.021]
    assert window.qs[-1] == pytest.approx([0.6] * 7)
    assert h.at(0.0205) == pytest.approx((0.5,) * 7)
    assert h.at(-5.0) == pytest.approx((0.0,) * 7)  # before the start: the oldest kept


def test_the_window_is_bounded_in_samples_and_in_time() -> None:
    h = history()
    for k in range(1, 2 * MAX_SAMPLES):
        h.add((k * 1e-6,) * 7, k * 0.01)
    window = h.window(-np.inf, np.inf)
    assert len(window) <= MAX_SAMPLES + 1  # HISTORY_S at 100 a second, both ends kept
    assert h.end == pytest.approx((2 * MAX_SAMPLES - 1) * 0.01)
    assert h.start >= h.end - HISTORY_S
    assert np.all(np.diff(window.times) > 0)
    assert h._qs.shape[0] < 2 * MAX_SAMPLES  # a quarter of slack, not a second copy


def test_markers_are_replayed_to_any_time_backwards_too() -> None:
    h = history()
    h.mark(marker(1.0), 1.0)
    h.mark(marker(2.0), 2.0)
    h.clear(3.0)
    h.mark(marker(4.0), 4.0)
    seen = {t: [m.position[0] for m in h.markers_at(t)[1]] for t in (0.5, 2.5, 3.5, 4.5)}
    assert seen == {0.5: [], 2.5: [1.0, 2.0], 3.5: [], 4.5: [4.0]}
    key_a, _ = h.markers_at(2.5)
    key_b, _ = h.markers_at(2.6)
    assert key_a == key_b  # nothing happened between: nothing to redraw
    assert [m.position[0] for m in h.markers_at(1.5)[1]] == [1.0]  # and back again


def test_a_flood_of_marks_folds_into_the_start_and_moves_it() -> None:
    h = history()
    h.add((0.0,) * 7, 10.0)
    for k in range(MAX_MARKER_EVENTS + 10):
        h.mark(marker(float(k)), 1.0 + k * 1e-4)
    assert len(h._marks) == MAX_MARKER_EVENTS
    assert h.start == pytest.approx(1.0 + 9 * 1e-4)  # what was folded cannot be shown
    shown = h.markers_at(h.start)[1]  # the ten folded ones, as they were then
    assert [m.position[0] for m in shown] == [float(k) for k in range(10)]
    last = h.markers_at(np.inf)[1]  # at the end, the newest MAX_MARKERS
    assert len(last) == 1000 and last[-1].position[0] == MAX_MARKER_EVENTS + 9


def test_objects_as_they_were() -> None:
    crate = WorkcellObject.__new__(WorkcellObject)  # identity is all the history looks at
    h = history()
    h.objects([crate], 2.0)
    h.objects([], 3.0)
    assert h.objects_at(1.0) == [] and h.objects_at(2.5) == [crate] and h.objects_at(3.5) == []


def test_thinning_keeps_the_ends() -> None:
    assert list(thin(5, 10)) == [0, 1, 2, 3, 4]
    picked = thin(10_000, 200)
    assert len(picked) <= 200 and picked[0] == 0 and picked[-1] == 9_999


def test_a_move_after_a_rest_is_a_step_not_a_ramp() -> None:
    """Issue 39, rough edge 8: an arm at rest sends nothing, so an instant move 35 s later
    was kept as a sample at 0 s and one at 35 s: a 35-second ramp on the plot."""
    h = RobotHistory(RobotState("arm", load_robot()), 0.01, 0.0, [], resting=True)
    h.add((0.3,) * 7, 35.0, resting=True)  # motion off: there at once, and resting
    window = h.window(-1.0, 40.0)
    assert list(window.times) == [0.0, 35.0, 35.0]  # held where it rested until the step
    assert window.qs[:, 0] == pytest.approx([0.0, 0.0, 0.3])
    assert h.at(34.9) == pytest.approx((0.0,) * 7) and h.at(35.0) == pytest.approx((0.3,) * 7)
    h.add((0.31,) * 7, 35.5)  # a move leaving after half a second at rest: a flat line first
    h.add((0.32,) * 7, 35.51)  # on its way: no step between frames
    assert list(h.window(-1.0, 40.0).times) == [0.0, 35.0, 35.0, 35.5, 35.5, 35.51]


def test_steps_keep_the_history_within_a_sample_a_period() -> None:
    h = history()
    for k in range(1, MAX_SAMPLES):  # a flood of instant moves, each at rest: no steps
        h.add((k * 1e-6,) * 7, k * 0.01, resting=True)
    assert len(h.window(-np.inf, np.inf)) == MAX_SAMPLES
    g = history()
    for k in range(1, MAX_SAMPLES):  # one every three periods: a step each, two samples
        g.add((k * 1e-6,) * 7, k * 0.03, resting=True)
    assert g.start <= g.end - HISTORY_S  # the whole window still kept


def test_thinning_keeps_the_corners_of_a_rest() -> None:
    times = np.concatenate([np.arange(1000) * 0.01, [35.0, 35.0], 35.0 + np.arange(1, 1000) * 0.01])
    picked = thin(len(times), 200, times)
    assert len(picked) <= 200 and picked[0] == 0 and picked[-1] == len(times) - 1
    assert {999, 1000, 1001} <= set(picked.tolist())  # the rest's end, the hold, the step


def _tool_point(state: RobotState, q: np.ndarray, tool: pin.SE3) -> np.ndarray:
    robot = state.robot
    return (robot.base_placement * robot.ee_pose(q) * tool).translation


def test_tool_points_are_those_of_the_tool_each_sample_was_taken_with() -> None:
    """The tool points are computed when a window is read, each with the tool the robot
    had when its sample came, also across a change of tool and the buffer's compaction."""
    h = history()
    state, old, new = h.state, h.state.tool, pin.SE3(np.eye(3), np.array([0.0, 0.0, 0.3]))
    count = MAX_SAMPLES + MAX_SAMPLES // 4 + 10  # past the compaction
    for k in range(1, count):
        h.add((np.sin(k * 1e-3),) * 7, k * 0.01)
        if k == count - 200:
            h.window(0.0, (count - 300) * 0.01)  # some computed before the change, some not
            state.tool = new
        if k == count - 100:
            h.window(0.0, (count - 150) * 0.01)
    window = h.window(-np.inf, np.inf)
    for row in (0, len(window) - 201, len(window) - 199, len(window) - 1):
        tool = old if window.times[row] < (count - 200 + 0.5) * 0.01 else new
        expected = _tool_point(state, window.qs[row], tool)
        assert window.tool[row] == pytest.approx(expected, abs=1e-12), row
