"""``fault latency`` at the CRCL door, on the virtual clock: every status comes that much
late, pushed or asked for, and in the order it was made (a jitter never reorders them)."""

from __future__ import annotations

from collections.abc import Iterator

import pytest
from crcl_support import DONE, CrclClient, CrclServerThread, command
from support import Client, load_robot

from c2rviz.session import ServerLimits
from c2rviz.world.virtual_clock import VirtualClock


@pytest.fixture
def virtual() -> Iterator[CrclServerThread]:
    """Both doors on a world whose clock is virtual."""
    server = CrclServerThread(load_robot("motoman_sia20d"), ServerLimits(), clock=VirtualClock())
    server.start()
    try:
        yield server
    finally:
        server.stop()


def now(server: CrclServerThread) -> float:
    return server.call(lambda: server.world.clock.now())


def fault(server: CrclServerThread, line: str) -> None:
    """``line`` from a text client that then leaves (an idle client holds virtual time)."""
    text = Client(server.host, server.port)
    try:
        assert text.ask(line) == "ok"
    finally:
        text.close()


def test_every_status_comes_late_by_the_latency(virtual: CrclServerThread, crcl_connect) -> None:
    client: CrclClient = crcl_connect(virtual)
    start = now(virtual)
    assert client.run(command("InitCanon", 1), 1).command_status.state == DONE
    assert now(virtual) == start  # no latency: on time
    fault(virtual, "fault latency 400")
    start = now(virtual)
    assert client.ask(2).command_status.command_id == 1  # asked for
    assert now(virtual) - start == pytest.approx(0.4)
    start = now(virtual)
    done = client.run(command("Message", 3, "<Message>late</Message>"), 3)  # pushed
    assert done.command_status.state == DONE
    assert now(virtual) - start == pytest.approx(0.4)
    fault(virtual, "fault clear latency")
    start = now(virtual)
    assert client.ask(4).command_status.command_id == 3
    assert now(virtual) == start


def test_jittered_statuses_keep_their_order(virtual: CrclServerThread, crcl_connect) -> None:
    client: CrclClient = crcl_connect(virtual)
    assert client.run(command("InitCanon", 1), 1).command_status.state == DONE
    fault(virtual, "fault latency 100,300")
    start = now(virtual)
    ids = list(range(10, 30))
    client.send(b"".join(command("GetStatus", i) for i in ids))  # one write
    statuses = [client.status() for _ in ids]  # CrclClient checks StatusID increases
    numbers = [s.command_status.status_id for s in statuses]
    assert numbers == sorted(numbers) and len(set(numbers)) == len(ids)
    # At least the base latency; no upper bound: the door holds no clock, so virtual time
    # may jump between two reads of the write, and the later documents run later.
    assert now(virtual) - start >= 0.1
