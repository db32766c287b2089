"""The part faults in the fault model alone (``world.faults.RobotFaults``): ``drop``
happens once, ``slip P`` draws once per grasp asked, from the generator given."""

from __future__ import annotations

import numpy as np

from c2rviz.world.faults import Fault, RobotFaults

NAMES = ("a", "b")
Q = (0.1, 0.2)


def test_a_drop_is_told_and_nothing_lasts():
    book = RobotFaults(NAMES, (False, False))
    assert book.start(Fault("drop"), 1.0, Q) == ["fault drop"]
    assert book.start(Fault("drop", word="p1"), 1.0, Q) == ["fault drop p1"]
    assert not book.any
    assert book.listing(0.0) == []


def test_slip_draws_from_the_generator_given_and_only_while_on():
    book = RobotFaults(NAMES, (False, False))
    rng = np.random.default_rng(7)
    assert not book.slips(rng)
    assert rng.random() == np.random.default_rng(7).random()  # no draw without the fault
    assert book.start(Fault("slip", values=(0.5,)), 2.0, Q) == ["fault slip 0.5"]
    assert book.any
    draws = [book.slips(np.random.default_rng(3)) for _ in range(3)]
    assert len(set(draws)) == 1  # the same seed, the same answer
    one = np.random.default_rng(9)
    expected = [float(v) < 0.5 for v in np.random.default_rng(9).random(20)]
    assert [book.slips(one) for _ in range(20)] == expected
    book.start(Fault("slip", values=(1.0,)), 3.0, Q)
    assert all(book.slips(one) for _ in range(50))
    book.start(Fault("slip", values=(0.0,)), 4.0, Q)
    assert not any(book.slips(one) for _ in range(50))
    assert [f.text(NAMES) + " " + when for f, when in book.listing(0.0)] == ["slip 0 since 2.000"]
    assert book.clear("slip") == ["cleared slip 0"]
    assert not book.slips(one)
