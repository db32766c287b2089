"""Reply texts: numbers print 10 significant digits, with no rounding noise around 0."""

from __future__ import annotations

import pytest

from c2rviz.protocol import replies


@pytest.mark.parametrize(
    ("values", "text"),
    [
        # `pose` at home on pybullet's panda, as Pinocchio computes it
        (
            [0.3854470958, -5.355525218e-12, 0.5184140276, 180, 0, -3.062492492e-10],
            "0.3854470958,0,0.5184140276,180,0,0",
        ),
        ([1e-9, -1e-9, 6.7e-17, -0.0, 0.0], "0,0,0,0,0"),
        ([2e-9, -2e-9], "2e-09,-2e-09"),  # just past the noise: kept
        ([1.5e-6, 0.001], "1.5e-06,0.001"),  # a micrometre is a real value
        ([90.0, -109.4, 2.5, 1 / 3], "90,-109.4,2.5,0.3333333333"),
        ([123456.789012345], "123456.789"),
        ([], ""),
    ],
    ids=["panda-home-pose", "noise", "past-noise", "small", "plain", "10-digits", "empty"],
)
def test_numbers(values: list[float], text: str) -> None:
    assert replies.numbers(values) == text


def test_a_value_below_the_noise_reads_back_as_0(server, connect) -> None:
    client = connect(server)
    assert client.ask("move 0,1 1e-10,-5e-12") == "ok"
    assert client.ask("where") == "ok 0,0,0,0,0,0,0"
    assert client.ask("move 0 3e-9") == "ok"
    assert client.ask("where") == "ok 3e-09,0,0,0,0,0,0"
