"""The one slack at a joint limit, shared by the server and the clients."""

from __future__ import annotations

import math
import subprocess
import sys

import pytest
from hypothesis import given
from hypothesis import strategies as st
from support import ROBOTS, load_robot

from c2rviz import errors
from c2rviz.errors import LIMIT_TOLERANCE, JointLimitError, limit_text, texts_apart, within_limit
from c2rviz.protocol import replies
from c2rviz.session import Services, Session
from c2rviz.world.world import World


@pytest.mark.parametrize(
    ("value", "lower", "upper", "inside"),
    [
        (0.0, -1.0, 1.0, True),
        (1.0, -1.0, 1.0, True),
        (1.0 + 0.5e-9, -1.0, 1.0, True),  # a rounding error past the limit
        (1.0 + 2e-9, -1.0, 1.0, False),
        (-1.0 - 0.5e-9, -1.0, 1.0, True),
        (-1.0 - 2e-9, -1.0, 1.0, False),
        (170.0 + 1e-7, -170.0, 170.0, True),  # relative to the limit: 1.7e-7 deg slack
        (170.0 + 1e-6, -170.0, 170.0, False),
        (1e300, -math.inf, math.inf, True),  # a continuous joint
        (math.nan, -1.0, 1.0, False),
    ],
)
def test_within_limit(value: float, lower: float, upper: float, inside: bool) -> None:
    assert within_limit(value, lower, upper) is inside


@pytest.mark.parametrize("name", sorted(ROBOTS))
def test_a_limit_printed_with_10_digits_is_within_it(name: str) -> None:
    """What `limits` and `where` print (10 significant digits) is accepted again."""
    robot = load_robot(name)
    for lower, upper in zip(robot.lower, robot.upper):
        for scale in (1.0, 180.0 / math.pi):
            low, high = lower * scale, upper * scale
            printed_low, printed_high = float(f"{low:.10g}"), float(f"{high:.10g}")
            assert within_limit(printed_low, low, high)
            assert within_limit(printed_high, low, high)
            assert within_limit(high, printed_low, printed_high)


def test_the_session_accepts_what_within_limit_accepts(monkeypatch: pytest.MonkeyPatch) -> None:
    """One tolerance: Session.to_si follows errors.within_limit, whatever its slack."""
    robot = load_robot()
    session = Session(Services(World(robot)))
    upper = robot.upper[1]
    assert session.to_si([1], [upper * (1 + 5e-10)]) == [upper]  # at the limit
    with pytest.raises(JointLimitError):
        session.to_si([1], [upper * (1 + 5e-4)])
    monkeypatch.setattr(errors, "LIMIT_TOLERANCE", 1e-3)
    assert session.to_si([1], [upper * (1 + 5e-4)]) == [upper]


@pytest.mark.parametrize(
    ("value", "limit", "texts"),
    [
        (89.99999999, 1.570796325 / (math.pi / 180), ("89.99999999", "89.9999999")),  # puma
        (3.1416000032, 3.1416, ("3.141600003", "3.1416")),
        (-2e-9, 0.0, ("-2e-09", "0")),
        (1.0000000000001, 1.0, ("1.0000000000001", "1")),  # equal at 10 digits: 14 differ
        (1.0000000000000002, 1.0, ("1.0000000000000002", "1")),  # the next float: 17
    ],
)
def test_a_refused_value_and_its_limit_print_apart(value, limit, texts) -> None:
    assert texts_apart(value, limit) == texts


def test_limits_errors_and_the_page_print_a_limit_alike() -> None:
    for limit in (1.570796325 * 180 / math.pi, -3.1416, 0.5, 1e-12, -math.inf):
        assert replies.limit(limit) == limit_text(limit) == replies.numbers([limit])


@given(
    lower=st.floats(-1e4, 1e4),
    width=st.floats(0, 1e4),
    past=st.floats(1e-12, 1e-3),
    above=st.booleans(),
)
def test_a_refused_value_never_looks_inside_the_printed_limits(lower, width, past, above):
    upper = lower + width
    value = upper + past * max(1, abs(upper)) if above else lower - past * max(1, abs(lower))
    if within_limit(value, lower, upper):
        return
    message = str(JointLimitError("j", 0, value, lower, upper, "deg"))
    shown_value = float(message.split(" = ")[1].split(" ")[0])
    shown_low, shown_high = map(float, message.split("limits ")[1].split(" ")[0].split(".."))
    assert shown_value > shown_high if above else shown_value < shown_low, message


def test_the_module_is_light() -> None:
    code = "import sys, c2rviz.errors; print(sorted(m for m in sys.modules if 'numpy' in m))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"
    assert LIMIT_TOLERANCE == 1e-9
