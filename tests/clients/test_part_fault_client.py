"""The client's fault methods pick up the part faults from ``FAULT_KINDS``: their lines,
and their bad arguments refused before anything is sent."""

from __future__ import annotations

import pytest

from c2rviz.clients.errors import ArgumentError
from c2rviz.clients.task_calls import clear_faults, fault


@pytest.mark.parametrize(
    ("args", "line"),
    [
        (("drop", (), None, None), "fault drop"),
        (("drop", ("p1",), None, None), "fault drop p1"),
        (("drop", ("p1",), None, 2), "fault after 2.0 drop p1"),
        (("slip", (0.5,), None, None), "fault slip 0.5"),
        (("slip", (1,), 3, None), "fault at 3.0 slip 1.0"),
    ],
)
def test_part_fault_lines(args, line):
    assert fault(*args).line == line


@pytest.mark.parametrize(
    ("args", "problem"),
    [
        (("slip", (2,), None, None), "slip P 2 is outside 0..1"),
        (("slip", (-1,), None, None), "slip P -1 is outside 0..1"),
        (("slip", (), None, None), "slip needs one P"),
        (("drop", ("p1", "p2"), None, None), "drop takes at most one PART"),
    ],
)
def test_bad_part_fault_arguments_are_refused_before_sending(args, problem):
    with pytest.raises(ArgumentError, match=problem):
        fault(*args)


def test_the_part_faults_clear():
    assert clear_faults("slip").line == "fault clear slip"
    assert clear_faults("drop").line == "fault clear drop"
