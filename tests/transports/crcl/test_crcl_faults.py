"""Faults on the CRCL door: an emergency stop cuts a move short and every status is
CRCL_Error until ``reset``; moves are refused; JointStatuses carry fault noise."""

from __future__ import annotations

import pytest
from crcl_support import DONE, ERROR, WORKING, CrclClient, actuate, command
from support import Client
from test_crcl_server import _wait_moving, started

STOPPED = "emergency stop since t="


@pytest.mark.wall_clock
def test_an_estop_is_crcl_error_until_reset(crcl_server, crcl_connect, connect) -> None:
    client: CrclClient = started(crcl_connect(crcl_server))
    text: Client = connect(crcl_server)
    client.send(actuate(2, {1: 2.5}))
    client.until(2, (WORKING,))
    _wait_moving(crcl_server)
    assert text.ask("fault estop") == "ok"
    stopped = client.until(2).command_status
    assert stopped.state == ERROR and STOPPED in stopped.description
    held = crcl_server.q
    assert 0.0 < held[0] < 2.5
    status = client.ask(50).command_status  # every status says so, the latest command's too
    assert status.state == ERROR and status.description.startswith(STOPPED)
    refused = client.run(actuate(3, {2: 0.3}), 3).command_status
    assert refused.state == ERROR and STOPPED in refused.description
    assert crcl_server.q == held
    assert text.ask("fault clear estop") == "ok"
    assert client.ask(51).command_status.description.endswith("(reset to move again)")
    assert text.ask("reset") == "ok"
    after = client.run(actuate(4, {2: 0.3}), 4).command_status
    assert after.state == DONE, after.description
    assert crcl_server.q[1] == pytest.approx(0.3)


def test_joint_statuses_carry_the_noise(crcl_server, crcl_connect, connect) -> None:
    client: CrclClient = started(crcl_connect(crcl_server))
    text: Client = connect(crcl_server)
    assert client.run(command("ConfigureJointReports", 2, _REPORTS), 2).command_status.state == DONE
    exact = [j.position for j in client.ask(3).joint_statuses.statuses]
    assert exact == [0.0] * 7
    assert text.ask("fault noise 0.01") == "ok"
    first = [j.position for j in client.ask(4).joint_statuses.statuses]
    second = [j.position for j in client.ask(5).joint_statuses.statuses]
    assert first != exact and first != second
    assert first == pytest.approx(exact, abs=0.06)
    assert text.ask("fault clear noise") == "ok"
    assert [j.position for j in client.ask(6).joint_statuses.statuses] == exact


_REPORTS = "<ResetAll>true</ResetAll>" + "".join(
    f"<ConfigureJointReport><JointNumber>{n}</JointNumber><ReportPosition>true</ReportPosition>"
    "<ReportVelocity>false</ReportVelocity><ReportTorqueOrForce>false</ReportTorqueOrForce>"
    "</ConfigureJointReport>"
    for n in range(1, 8)
)


def test_disconnect_closes_the_robots_crcl_clients(crcl_server, crcl_connect, connect) -> None:
    client: CrclClient = started(crcl_connect(crcl_server))
    text: Client = connect(crcl_server)
    assert text.ask("fault disconnect") == "ok"
    assert client.closed_by_server()
    again: CrclClient = started(crcl_connect(crcl_server))  # it may come back
    assert again.ask(9).command_status.state == DONE
