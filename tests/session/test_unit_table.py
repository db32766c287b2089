"""``UnitTable.within`` on a run of configurations (the batched ``joints`` path) answers as
checking each configuration alone, and ``numbers_batch`` reads a run only when every line
holds exactly n plain values."""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st
from support import load_robot

from c2rviz.protocol.grammar import numbers_batch
from c2rviz.session.units import UnitTable

TABLE = UnitTable.build(load_robot("motoman_sia20d"), degrees=False)
N = len(TABLE.lower)

value = st.floats(min_value=-4.0, max_value=4.0) | st.sampled_from([math.nan, math.inf, -math.inf])


def _alone(values: list[float]) -> bool:
    return all(
        math.isfinite(v) and TABLE.lower[i % N] <= v <= TABLE.upper[i % N]
        for i, v in enumerate(values)
    )


@given(st.lists(st.lists(value, min_size=N, max_size=N), min_size=1, max_size=6))
def test_a_run_is_within_when_each_configuration_is(configs: list[list[float]]) -> None:
    flat = [v for config in configs for v in config]
    assert TABLE.within(flat) == _alone(flat) == all(TABLE.within(c) for c in configs)


def test_one_value_past_a_limit_anywhere_in_a_run_is_seen() -> None:
    inside = [0.0] * N
    for config in range(3):
        for joint in range(N):
            for past in (TABLE.lower[joint] - 1e-9, TABLE.upper[joint] + 1e-9):
                flat = inside * 3
                flat[config * N + joint] = past
                assert not TABLE.within(flat), (config, joint, past)
    assert TABLE.within(inside * 3)


@pytest.mark.parametrize(
    ("texts", "expected"),
    [
        (["1,2", "3,4"], [1.0, 2.0, 3.0, 4.0]),
        (["1,2\r", "3,4\r"], [1.0, 2.0, 3.0, 4.0]),  # CRLF lines
        (["1,2,3", "4"], None),  # the counts add up, but not line by line
        (["1\r,2", "3,4"], None),  # a \r inside a list
        (["1,2", "3,"], None),
        (["1,2", "3,x"], None),
    ],
    ids=["plain", "crlf", "uneven", "cr-inside", "empty", "letter"],
)
def test_numbers_batch(texts: list[str], expected: list[float] | None) -> None:
    assert numbers_batch(texts, 2) == expected
