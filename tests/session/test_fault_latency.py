"""``fault latency`` on the text door, on the virtual clock: every reply comes late alike,
``ok`` and error, at once or waited for; nothing else changes (issue 38)."""

from __future__ import annotations

import pytest

STALLED = "0.2,0.6,0,0,0,0,0"  # needs joint_l, which `fault stall joint_l` holds at 0
ZERO = "ok 0,0,0,0,0,0,0"


def timed(server, client, line: str) -> tuple[str, float]:
    """``line``'s reply and how long it took on the world's clock [s]."""
    start = server.now()
    reply = client.ask(line)
    return reply, server.now() - start


@pytest.mark.c2rviz(clock="virtual")
def test_error_replies_come_as_late_as_ok_ones(c2rviz_server, connect):
    client = connect(c2rviz_server)
    assert client.ask("fault latency 250") == "ok"
    for line, error in [
        ("bogus", "error: unknown command"),
        ("joints 9,9,9,9,9,9,9", "error: "),
        ("fault stall joint_q", "error: fault: no joint 'joint_q'"),
        ("where", ZERO[:2]),
    ]:
        reply, took = timed(c2rviz_server, client, line)
        assert reply.startswith(error), (line, reply)
        assert took == pytest.approx(0.25), line
    assert client.ask("fault clear latency") == "ok"
    reply, took = timed(c2rviz_server, client, "bogus")  # on time again
    assert reply.startswith("error: unknown command") and took == 0.0
    assert client.ask("where") == ZERO  # the refused lines changed nothing
    assert client.ask("faults") == "ok none"


@pytest.mark.c2rviz(clock="virtual", motion="on")
def test_an_error_a_move_ends_with_comes_late_after_its_arrival(c2rviz_server, connect):
    client = connect(c2rviz_server)
    assert client.ask("fault stall joint_l") == "ok"
    reply, on_time = timed(c2rviz_server, client, f"joints {STALLED}")
    assert reply == "error: joint_l stalled at 0 rad" and on_time > 0.0
    assert client.ask("joints 0,0,0,0,0,0,0") == "ok"  # back (joint_l never left 0)
    assert client.ask("fault latency 300") == "ok"
    reply, took = timed(c2rviz_server, client, f"joints {STALLED}")
    assert reply == "error: joint_l stalled at 0 rad"
    assert took == pytest.approx(on_time + 0.3)


@pytest.mark.c2rviz(clock="virtual")
def test_jittered_replies_keep_their_order_and_stay_within_the_range(c2rviz_server, connect):
    client = connect(c2rviz_server)
    assert client.ask("fault latency 100,50") == "ok"
    lines = ["where", "bogus", "names", "joints 9", "where"]
    start = c2rviz_server.now()
    client.send("".join(line + "\n" for line in lines))  # one write: each waits its turn
    replies = [client.read_line() for _ in lines]
    took = c2rviz_server.now() - start
    assert [r.split(" ")[0] for r in replies] == ["ok", "error:", "ok", "error:", "ok"]
    assert 5 * 0.1 <= took <= 5 * 0.15 + 1e-9
