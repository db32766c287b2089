"""The fault model alone (``world.faults.RobotFaults``): no clock, no server."""

from __future__ import annotations

import numpy as np
import pytest

from c2rviz.errors import EmergencyStop, JointStalled, ProtectiveStop
from c2rviz.world.faults import MAX_SCHEDULED, Fault, RobotFaults, Scheduled, TooManyScheduled

NAMES = ("a", "b", "c")
Q = (0.1, 0.2, 0.3)


def faults() -> RobotFaults:
    return RobotFaults(NAMES, (False, False, True))


def test_no_fault_changes_nothing():
    book = faults()
    rng = np.random.default_rng(0)
    assert not book.any
    assert book.refusal(0.0) is None
    assert book.follow(Q) is Q
    assert book.stalled((9.0, 9.0, 9.0)) is None
    assert book.sensed(Q, rng) is Q
    assert book.delay_s(rng) == 0.0
    assert book.listing(0.0) == []
    assert book.reset(0.0) == []


def test_an_estop_holds_until_cleared_and_reset():
    book = faults()
    assert book.start(Fault("estop"), 12.0, Q) == ["fault estop"]
    error = book.refusal(2.0)
    assert isinstance(error, EmergencyStop)
    assert str(error) == "emergency stop since t=10.000 (fault clear estop, then reset)"
    with pytest.raises(EmergencyStop, match="fault clear estop, then reset"):
        book.reset(2.0)
    assert book.clear("estop") == ["cleared estop"]
    assert str(book.refusal(2.0)) == "emergency stop since t=10.000 (reset to move again)"
    assert book.listing(2.0) == [(Fault("estop"), "released, reset needed since 10.000")]
    assert book.reset(2.0) == ["reset"]
    assert book.refusal(2.0) is None
    assert not book.any


def test_a_second_estop_keeps_the_first_time_and_engages_again():
    book = faults()
    book.start(Fault("estop"), 1.0, Q)
    book.clear("estop")
    book.start(Fault("estop"), 5.0, Q)
    assert str(book.refusal(0.0)) == "emergency stop since t=1.000 (fault clear estop, then reset)"


def test_a_protective_stop_holds_until_reset():
    book = faults()
    book.start(Fault("protective"), 3.0, Q)
    assert isinstance(book.refusal(0.0), ProtectiveStop)
    assert str(book.refusal(0.0)) == "protective stop since t=3.000 (reset to move again)"
    assert book.reset(0.0) == ["cleared protective", "reset"]
    assert book.refusal(0.0) is None


def test_an_estop_outranks_a_protective_stop():
    book = faults()
    book.start(Fault("protective"), 1.0, Q)
    book.start(Fault("estop"), 2.0, Q)
    assert isinstance(book.refusal(0.0), EmergencyStop)


def test_a_stalled_joint_holds_its_value_and_names_it():
    book = faults()
    assert book.start(Fault("stall", joint=1), 0.0, Q) == ["fault stall b"]
    assert book.follow((1.0, 1.0, 1.0)) == (1.0, 0.2, 1.0)
    assert book.stalled((1.0, 0.2, 1.0)) is None  # the target needs b where it is
    error = book.stalled((1.0, 0.5, 1.0))
    assert isinstance(error, JointStalled)
    assert str(error) == "b stalled at 0.2 rad"
    book.start(Fault("stall", joint=2), 0.0, Q)
    assert str(book.stalled((0.1, 0.2, 0.9))) == "c stalled at 0.3 m"  # prismatic
    assert book.clear("stall") == ["cleared stall b", "cleared stall c"]
    assert book.follow((1.0, 1.0, 1.0)) == (1.0, 1.0, 1.0)


def test_noise_is_drawn_from_the_generator_given():
    book = faults()
    book.start(Fault("noise", sigma=0.01), 0.0, Q)
    first = book.sensed(Q, np.random.default_rng(7))
    again = book.sensed(Q, np.random.default_rng(7))
    assert first == again != Q
    assert max(abs(a - b) for a, b in zip(first, Q)) < 0.1


def test_latency_adds_at_most_its_jitter():
    book = faults()
    book.start(Fault("latency", delay_s=0.05, jitter_s=0.01), 0.0, Q)
    rng = np.random.default_rng(1)
    delays = [book.delay_s(rng) for _ in range(100)]
    assert all(0.05 <= d <= 0.06 for d in delays)
    assert len(set(delays)) > 1
    assert book.listing(0.0)[0][0].text(NAMES) == "latency 50,10"


def test_a_disconnect_happens_once():
    book = faults()
    assert book.start(Fault("disconnect"), 0.0, Q) == ["fault disconnect"]
    assert not book.any


def test_scheduled_faults_come_in_order_and_clear_takes_them():
    book = faults()
    book.add_scheduled(Scheduled(5.0, 1, Fault("estop")))
    book.add_scheduled(Scheduled(2.0, 2, Fault("noise", sigma=0.1)))
    book.add_scheduled(Scheduled(2.0, 3, Fault("protective")))
    assert [s.fault.kind for s in book.due_now(2.0)] == ["noise", "protective"]
    assert [text for _, text in book.listing(0.0)] == ["at 5.000"]
    book.clear("estop")
    assert book.scheduled == []


def test_too_many_scheduled_faults_are_refused():
    book = faults()
    for k in range(MAX_SCHEDULED):
        book.add_scheduled(Scheduled(float(k), k, Fault("estop")))
    with pytest.raises(TooManyScheduled, match=f"{MAX_SCHEDULED} faults are scheduled"):
        book.add_scheduled(Scheduled(1.0, 999, Fault("estop")))
    assert len(book.scheduled) == MAX_SCHEDULED


def test_clear_all_ends_everything():
    book = faults()
    book.start(Fault("stall", joint=0), 0.0, Q)
    book.start(Fault("noise", sigma=0.1), 0.0, Q)
    book.start(Fault("protective"), 0.0, Q)
    book.add_scheduled(Scheduled(9.0, 1, Fault("estop")))
    assert len(book.clear("all")) == 3
    assert not book.any and not book.held and not book.scheduled


def test_a_kind_to_come_is_kept_per_word_and_said_whole():
    book = faults()
    blackout = Fault("blackout", word="cam1", values=(2.0,))
    assert blackout.key == "blackout cam1" and blackout.text(NAMES) == "blackout cam1 2"
    book.start(blackout, 0.0, Q)
    book.start(Fault("blackout", word="cam2"), 0.0, Q)
    assert len(book.active) == 2
    assert book.clear("blackout") == ["cleared blackout cam1 2", "cleared blackout cam2"]
