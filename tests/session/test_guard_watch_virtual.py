"""The guard's re-check of a running move under ``--clock virtual`` (issue 35): a wall put
in a guarded move's path mid-move stops it short, and its waiting reply comes. The
re-check runs on the worker while every client waits: the clock stands still until it
answers (before, time jumped to the move's end meanwhile, and the arm went through)."""

from __future__ import annotations

import time
from typing import Any

import pytest
from support import Client, ServerLimits, ServerThread, load_robot

from c2rviz.session import guard_watch
from c2rviz.world.virtual_clock import VirtualClock

WALL = "object wall box 0.05,2,2 0.6,0,0.9,0,0,0"  # in the way of the arm lying down


def test_a_wall_put_in_a_running_guarded_move_stops_it_on_a_virtual_clock(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    real = guard_watch._first_hit

    def slow(*args: Any) -> Any:  # a re-check as a loaded machine runs it (on the worker)
        time.sleep(0.2)
        return real(*args)

    monkeypatch.setattr(guard_watch, "_first_hit", slow)
    server = ServerThread(load_robot("motoman_sia20d"), ServerLimits(), clock=VirtualClock())
    server.start()
    mover = Client(server.host, server.port, timeout=60.0)
    builder = Client(server.host, server.port, timeout=60.0)
    try:
        for line in ("degrees", "guard on", "speed 5", "motion on"):
            assert mover.ask(line) == "ok", line
        mover.send("joints 0,90,0,0,0,0,0\n")  # lie down along +x: clear now, seconds long
        name = next(iter(server.world.robots))
        for _ in range(100_000):  # (the builder holds the clock: time stands still)
            if server.call(server.world.moving, name):
                break
        else:
            raise AssertionError("the guarded move never started")
        far = "".join(f"object far{k} box 0.1,0.1,0.1 -1,-1,{k},0,0,0\n" for k in range(5))
        builder.send(f"{WALL}\n{far}sleep 600\n")  # then the builder waits too: time may run
        assert [builder.read_line() for _ in range(6)] == ["ok"] * 6  # re-checks, follow-ups
        reply = mover.read_line()
        assert reply.startswith("error: ") and "wall" in reply, reply
        q = [float(v) for v in mover.ask("where")[3:].split(",")]
        assert q[1] < 45.0  # stopped short of the wall (where the re-check found it)
    finally:
        mover.close()
        builder.close()
        server.stop()
