"""The one slack at a joint limit, shared by the server and the clients."""

from __future__ import annotations

import math
import subprocess
import sys

import pytest
from conftest import ROBOTS, load_robot

from c2rviz.tolerance import LIMIT_TOLERANCE, within_limit


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


def test_the_module_is_light() -> None:
    code = "import sys, c2rviz.tolerance; print(sorted(m for m in sys.modules if 'numpy' in m))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"
    assert LIMIT_TOLERANCE == 1e-9
