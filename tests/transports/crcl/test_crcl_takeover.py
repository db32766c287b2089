"""A CRCL move taken over while it plans, and MoveThroughTo's waypoints (issue 39, fault 1
and rough edge 6; issue 35: the legs are checked off the event loop).

A move that cannot be planned is ``CRCL_Error`` with its reason even when a newer
move takes it over while it plans, and no future is left with an unread error; a
MoveThroughTo error names the waypoint (1-based); its legs are checked on the
session's worker, never on the loop.
"""

from __future__ import annotations

import gc
import threading
from typing import Any

import numpy as np
import pytest
from crcl_support import DONE, ERROR, CrclServerThread, command, move_to, pose

from c2rviz.session import calls

REACH = (0.5, 0.0, 0.8)  # tool down: the motoman reaches it from home
OTHER = (0.6, 0.2, 0.6)
FAR = (3.0, 0.0, 0.8)  # 3000 mm: beyond either arm


def _home_pose(server: CrclServerThread) -> dict[str, Any]:
    """The tool pose at home (point, x and z axes), as ``move_to`` takes it."""
    placement = server.call(lambda: server.world.ee_pose())
    rotation = np.asarray(placement.rotation)
    point = tuple(float(v) for v in placement.translation)
    return {
        "point": point,
        "x_axis": tuple(round(float(v), 12) for v in rotation[:, 0]),
        "z_axis": tuple(round(float(v), 12) for v in rotation[:, 2]),
    }


def _errors_kept(server: CrclServerThread) -> list[dict[str, Any]]:
    """Collect what the server's loop reports to its exception handler from now on."""
    seen: list[dict[str, Any]] = []
    server.call(lambda: server.loop.set_exception_handler(lambda loop, ctx: seen.append(ctx)))
    return seen


def _through(command_id: int, points: list[tuple[float, float, float]]) -> bytes:
    body = "    <MoveStraight>false</MoveStraight>\n"
    body += "\n".join(pose("Waypoint", p) for p in points)
    body += f"\n    <NumPositions>{len(points)}</NumPositions>"
    return command("MoveThroughTo", command_id, body)


@pytest.mark.parametrize("robot", ["motoman_sia20d", "fanuc_lrmate200id"])
def test_an_unreachable_move_taken_over_at_once_is_an_error(
    start_crcl, crcl_connect, robot: str
) -> None:
    server = start_crcl(robot)
    seen = _errors_kept(server)
    home = _home_pose(server)
    x, y, z = home["point"]
    axes = {"x_axis": home["x_axis"], "z_axis": home["z_axis"]}
    client = crcl_connect(server)
    assert client.run(command("InitCanon", 1), 1).command_status.state == DONE
    client.send(move_to(2, FAR, **axes) + move_to(3, (x, y, z - 0.05), **axes))
    finals = {}
    while len(finals) < 2:
        state = client.status().command_status
        if state.command_id in (2, 3) and state.state in (DONE, ERROR):
            finals[state.command_id] = state
    first = finals[2]
    assert first.state == ERROR, first.description
    assert first.description.startswith("MoveToType (CommandID 2): pose unreachable")
    assert finals[3].state == DONE, finals[3].description
    server.call(gc.collect)  # a future dropped with an unread error is reported when freed
    assert not [c for c in seen if "never retrieved" in str(c.get("message"))], seen


def test_a_move_taken_over_while_it_plans_does_not_move(crcl_server, crcl_connect) -> None:
    client = crcl_connect(crcl_server)
    assert client.run(command("InitCanon", 1), 1).command_status.state == DONE
    client.send(move_to(2, REACH) + move_to(3, OTHER))
    assert client.until(3).command_status.state == DONE
    old = [s.command_status for s in client.seen if s.command_status.command_id == 2]
    assert old[-1].state == DONE
    assert old[-1].description == (
        "MoveToType (CommandID 2): taken over by MoveToType (CommandID 3) before it moved"
    )
    tool = crcl_server.call(lambda: crcl_server.world.ee_pose().translation.copy())
    np.testing.assert_allclose(tool, OTHER, atol=1e-6)


def test_a_move_through_error_names_its_waypoint(crcl_server, crcl_connect) -> None:
    client = crcl_connect(crcl_server)
    assert client.run(command("InitCanon", 1), 1).command_status.state == DONE
    before = crcl_server.q
    status = client.run(_through(2, [REACH, OTHER, FAR]), 2).command_status
    assert status.state == ERROR
    assert status.description.startswith(
        "MoveThroughToType (CommandID 2): waypoint 3 of 3: pose unreachable"
    ), status.description
    assert crcl_server.q == before  # nothing moved


def test_a_move_through_checks_its_legs_off_the_loop(
    crcl_server, crcl_connect, monkeypatch
) -> None:
    threads: list[int] = []
    check = calls._check

    def recording(*args: Any) -> None:
        threads.append(threading.get_ident())
        check(*args)

    monkeypatch.setattr(calls, "_check", recording)
    client = crcl_connect(crcl_server)
    assert client.run(command("InitCanon", 1), 1).command_status.state == DONE
    status = client.run(_through(2, [REACH, OTHER, REACH]), 2).command_status
    assert status.state == DONE, status.description
    assert len(threads) == 2  # the legs after the first (the first is checked as it starts)
    assert crcl_server.thread.ident not in threads
