"""``assert_part_at`` and ``assert_goals_met``: pass when true, and say which part is
where when not."""

from __future__ import annotations

import pytest
from support import ServerLimits, ServerThread, load_robot

from c2rviz import Client
from c2rviz.testing import assert_goals_met, assert_part_at
from c2rviz.world.virtual_clock import VirtualClock


@pytest.fixture
def client():
    server = ServerThread(load_robot("fanuc_lrmate200id"), ServerLimits(), clock=VirtualClock())
    server.start()
    try:
        with Client(server.host, server.port, degrees=True) as connected:
            yield connected
    finally:
        server.stop()


def test_assert_part_at(client: Client) -> None:
    client.send("part p1 box 0.05,0.05,0.05 0.5,0.5,0.025,0,0,10")
    assert_part_at(client, "p1", (0.5, 0.5, 0.025))
    assert_part_at(client, "p1", (0.5005, 0.5, 0.025, 0, 0, 9), tol=0.001, tol_angle=1.5)
    with pytest.raises(AssertionError, match=r"part p1 is at 0.5,0.5,0.025,0,0,10 \(resting on "):
        assert_part_at(client, "p1", (0.6, 0.5, 0.025))
    with pytest.raises(AssertionError, match="turned 10 off"):
        assert_part_at(client, "p1", (0.5, 0.5, 0.025, 0, 0, 0), tol_angle=1)
    with pytest.raises(AssertionError, match=r"no part named 'p9' \(parts: p1\)"):
        assert_part_at(client, "p9", (0, 0, 0))


def test_assert_goals_met(client: Client) -> None:
    with pytest.raises(AssertionError, match="no goals are set"):
        assert_goals_met(client)
    client.send("part p1 box 0.05,0.05,0.05 0.5,0.5,0.025,0,0,0")
    client.send("goal p1 0.5,0.5,0.025,0,0,0")
    assert_goals_met(client)
    client.send("goal type=gear 0,0,0,0,0,0")
    with pytest.raises(AssertionError, match=r"1/2 met; type=gear missing; parts: ok p1:"):
        assert_goals_met(client)
