"""The guard made safe (issue 23, items 2, 3 and 6), through the real server.

2. A stop (and a guarded preemption) brakes along the path the guard checked, at the
   joints' full limits: every joint stops at one common fraction, quickly at any speed.
3. A new object re-checks the running guarded moves: the arm stops before it and its
   mover hears why; a move that leaves a contact is allowed, one that pushes into a new
   pair is not.
6. Guarded checks run on the worker's thread, off the event loop: a bystander is served
   while they wait; the world changing meanwhile is checked again; the worker's queue is
   bounded; the newest of one source's waiting moves wins.

Judged from the frames the world published (their clock times) and the replies, never
from how long the test took.
"""

from __future__ import annotations

import asyncio
import math
import re
import threading
import time
from collections.abc import Callable

import numpy as np
import pytest
from support import Client, ServerThread

from c2rviz.errors import C2rvizError
from c2rviz.session import Session

FAR = "90,45,0,-30,0,60,0"  # degrees, motoman_sia20d: the move
OTHER = "-45,20,30,0,0,-30,0"
WALL = "object wall box 0.2,0.2,0.2 0,0.8,0.85,0,0,0"  # where the arm swung to +y passes
REACH = "0,60,0,0,0,0,0"  # the arm held out along +x
INTO = "90,60,0,0,0,0,0"  # ... swung round to +y: through the wall


@pytest.fixture
def open_client(server: ServerThread, connect) -> Callable[..., Client]:
    def open_client(*lines: str) -> Client:
        opened = connect(server)
        for line in ("degrees", *lines):
            assert opened.ask(line) == "ok", line
        return opened

    return open_client


def frames(server: ServerThread, since: int = 0) -> tuple[np.ndarray, np.ndarray]:
    times, joints = server.call(lambda: (list(server.scene.times), list(server.scene.joints)))
    return np.array(times[since:]), np.array(joints[since:])


def frame_count(server: ServerThread) -> int:
    return server.call(lambda: len(server.scene.joints))


WAIT_S = 100.0
"""How long a wait on the arm may take before it fails (the suite's limit is 120 s): a
condition, polled; the bound only tells a stuck arm from a busy machine."""


def ask_until(client: Client, line: str, done: Callable[[str], bool], what: str) -> str:
    """Ask ``line`` until its reply is ``done``; fail after ``WAIT_S`` naming ``what``."""
    deadline = time.monotonic() + WAIT_S
    while not done(reply := client.ask(line)):
        assert time.monotonic() < deadline, f"{what} in {WAIT_S:.0f} s (last: {reply!r})"
    return reply


def wait_until_moving(client: Client) -> None:
    ask_until(client, "status", lambda r: r.startswith("ok moving"), "the arm never moved")


def wait_until_past(client: Client, joint: int, degrees: float) -> None:
    ask_until(
        client,
        "where",
        lambda reply: abs(float(reply[3:].split(",")[joint])) >= degrees,
        f"joint {joint} never passed {degrees} degrees",
    )


def fractions_along(q: np.ndarray, start: np.ndarray, goal: np.ndarray) -> np.ndarray:
    """Each moving joint's fraction of its travel from ``start`` to ``goal``."""
    travel = goal - start
    moved = np.abs(travel) > 1e-12
    return (q - start)[moved] / travel[moved]


def colliding_frames(server: ServerThread, since: int) -> list[tuple[str, str]]:
    """Pairs any published frame from ``since`` on collides in (checked on the loop)."""
    _, qs = frames(server, since)

    def check() -> list[tuple[str, str]]:
        model = server.world.collision_model()
        return sorted({pair for q in qs for pair in model.colliding(q)})

    return server.call(check)


# --- 23.2: a stop brakes along the checked path at the full limits ------------------------


@pytest.mark.parametrize("speed", [100, 20, 5])
@pytest.mark.wall_clock
def test_a_stop_brakes_along_the_checked_path_at_the_full_limits(
    server: ServerThread, open_client, speed: int
):
    robot = server.robot
    start, goal = np.zeros(robot.n), np.radians([90, 45, 0, -30, 0, 60, 0])
    beside = robot.ee_pose((0.6 * goal).tolist()).translation + [0.0, 0.0, 0.14]
    mover = open_client(f"object ball sphere 0.06 {','.join(map(str, beside))}")
    mover_lines = ("guard on", "motion on", f"speed {speed}")
    for line in mover_lines:
        assert mover.ask(line) == "ok"
    stopper = open_client()
    since = frame_count(server)
    mover.send(f"j {FAR}\n")
    wait_until_moving(stopper)
    wait_until_past(stopper, 0, 1.0)
    stop_at = server.call(server.world.clock.now)
    assert stopper.ask("stop") == "ok"  # the reply comes at rest
    assert re.fullmatch(r"error: motion stopped by tcp 127\.0\.0\.1:\d+", mover.read_line())
    t, qs = frames(server, since)
    for q in qs:  # every joint at one common fraction: on the segment the guard checked
        assert np.ptp(fractions_along(q, start, goal)) < 1e-9, np.degrees(q)
    rest = fractions_along(qs[-1], start, goal)[0]
    assert 0 < rest < 1
    assert stopper.ask("collisions") == "ok none"
    rested_after = t[-1] - stop_at
    assert rested_after < 1.0, f"rest {rested_after:.2f} s after the stop at speed {speed}"


@pytest.mark.wall_clock
def test_a_guarded_preemption_brakes_on_the_path_then_goes(server: ServerThread, open_client):
    first = open_client("guard on", "motion on", "speed 30")
    second = open_client("guard on", "motion on", "speed 100")
    since = frame_count(server)
    first.send(f"j {FAR}\n")
    wait_until_moving(second)
    wait_until_past(second, 0, 5.0)
    assert second.ask(f"j {OTHER}") == "ok"
    assert re.fullmatch(r"error: preempted by tcp 127\.0\.0\.1:\d+", first.read_line())
    _, qs = frames(server, since)
    start, far, other = np.zeros(7), np.radians(degrees_of(FAR)), np.radians(degrees_of(OTHER))
    on_first = [np.ptp(fractions_along(q, start, far)) < 1e-9 for q in qs]
    turn = on_first.index(False)  # the frames leave the first segment once, at rest
    assert all(on_first[:turn]) and not any(on_first[turn:])
    rest = qs[turn - 1]
    for q in qs[turn:]:
        assert np.ptp(fractions_along(q, rest, other)) < 1e-9
    np.testing.assert_allclose(qs[-1], other, atol=1e-12)


def degrees_of(text: str) -> np.ndarray:
    return np.array([float(v) for v in text.split(",")])


# --- 23.3: the guard protects a move already running -------------------------------------


@pytest.mark.wall_clock
def test_a_new_object_stops_a_running_guarded_move_before_it(server: ServerThread, open_client):
    mover = open_client(f"j {REACH}", "guard on", "motion on", "speed 20")
    other = open_client()
    since = frame_count(server)
    mover.send(f"j {INTO}\n")
    wait_until_moving(other)
    wait_until_past(other, 0, 2.0)
    assert other.ask(WALL) == "ok"
    reply = mover.read_line()
    assert re.fullmatch(r"error: stopped: link_\w+ would hit wall \(the workcell changed\)", reply)
    assert colliding_frames(server, since) == []
    assert mover.ask("collisions") == "ok none"
    assert mover.ask(f"j {REACH}") == "ok"  # away: free
    reply = mover.ask(f"j {INTO}")
    assert re.fullmatch(r"error: link_\w+ would hit wall at \d+% of the move", reply), reply


def test_a_move_leaving_a_contact_goes_and_one_touching_a_new_pair_does_not(
    server: ServerThread, open_client
):
    mover = open_client(WALL, f"j {INTO}")  # unguarded: shown in the wall
    touching = mover.ask("collisions")
    assert re.fullmatch(r"ok (link_\w+~wall,?)+", touching), touching
    for line in ("guard on", "motion on", "speed 100"):
        assert mover.ask(line) == "ok"
    assert mover.ask("j 90,60,0,0,0,0,90") == "ok"  # the last joint turns, still in the wall
    assert mover.ask("collisions") == touching
    # bending the wrist brings link_t into the wall too: a new pair
    reply = mover.ask("j 90,60,0,0,0,-90,90")
    assert re.fullmatch(r"error: link_t would hit wall at \d+% of the move", reply), reply
    assert mover.ask(f"j {REACH}") == "ok"  # leaving the wall goes
    assert mover.ask("collisions") == "ok none"
    reply = mover.ask(f"j {INTO}")  # cleared: touching it again is refused
    assert re.fullmatch(r"error: link_\w+ would hit wall at \d+% of the move", reply), reply


# --- 23.6: guarded work off the event loop -------------------------------------------------


class Blocker:
    """Holds the worker's thread with a job of our own until ``release``."""

    def __init__(self, server: ServerThread) -> None:
        self.server = server
        self.event = threading.Event()
        self.started = threading.Event()

        def hold() -> None:
            self.started.set()
            self.event.wait(60)

        server.call(lambda: server.services.worker.run(hold))
        assert self.started.wait(60)

    def release(self) -> None:
        self.event.set()


def waiting(server: ServerThread) -> int:
    return server.call(lambda: server.services.worker.waiting)


def wait_for_waiting(server: ServerThread, count: int) -> None:
    for _ in range(100_000):
        if waiting(server) >= count:
            return
    raise AssertionError(f"never {count} jobs waiting")


def test_a_guarded_check_waits_on_the_worker_while_a_bystander_is_served(
    server: ServerThread, open_client
):
    mover = open_client("guard on")
    bystander = open_client()
    blocker = Blocker(server)
    try:
        mover.send(f"j {REACH}\n")
        wait_for_waiting(server, 1)  # the check waits for the worker's thread
        for _ in range(20):
            assert bystander.ask("where") == "ok 0,0,0,0,0,0,0"
    finally:
        blocker.release()
    assert mover.read_line() == "ok"
    assert bystander.ask("where") == f"ok {REACH}"


def test_the_world_changing_during_a_check_is_checked_again(server: ServerThread, open_client):
    mover = open_client("guard on")
    other = open_client()
    blocker = Blocker(server)
    try:
        mover.send(f"j {INTO}\n")  # free now: checked against no wall
        wait_for_waiting(server, 1)
        assert other.ask(WALL) == "ok"  # ... while it waits, the wall comes
    finally:
        blocker.release()
    reply = mover.read_line()
    assert re.fullmatch(r"error: link_\w+ would hit wall at the target", reply), reply
    assert mover.ask("where") == "ok 0,0,0,0,0,0,0"


def test_a_full_worker_queue_refuses_with_a_clear_error(server: ServerThread, open_client):
    server.call(lambda: setattr(server.services.worker, "max_queue", 1))
    first, second = open_client("guard on"), open_client("guard on")
    blocker = Blocker(server)
    try:
        first.send(f"j {REACH}\n")
        wait_for_waiting(server, 1)
        reply = second.ask("rand")
        assert reply == (
            "error: the server is busy: 1 heavy commands (checks, IK, plans) wait already, "
            "its limit; try again"
        )
    finally:
        blocker.release()
    assert first.read_line() == "ok"
    assert second.ask("where") == f"ok {REACH}"


def test_the_newest_of_one_sources_waiting_moves_wins(server: ServerThread):
    blocker = Blocker(server)

    async def two_moves() -> list[object]:
        session = Session(server.services, source="page")
        assert session.run("guard on") == "ok"
        assert session.run("degrees") == "ok"
        older = asyncio.ensure_future(session.run("j 10,0,0,0,0,0,0"))  # type: ignore[arg-type]
        await asyncio.sleep(0.05)
        newer = asyncio.ensure_future(session.run("j 20,0,0,0,0,0,0"))  # type: ignore[arg-type]
        await asyncio.sleep(0.05)
        blocker.release()
        return list(await asyncio.gather(older, newer, return_exceptions=True))

    older, newer = server.call_async(two_moves())
    assert isinstance(older, C2rvizError)
    assert str(older) == "superseded by a newer command before it was checked"
    assert newer == "ok"
    np.testing.assert_allclose(server.q, [math.radians(20), 0, 0, 0, 0, 0, 0], atol=1e-12)


def test_a_newer_command_that_moves_the_arm_during_a_check_wins(server: ServerThread, open_client):
    mover = open_client("guard on", "motion on")
    other = open_client()
    blocker = Blocker(server)
    try:
        mover.send(f"j {REACH}\n")
        wait_for_waiting(server, 1)
        assert other.ask(f"j {OTHER}") == "ok"  # unguarded, shown at once
    finally:
        blocker.release()
    assert mover.read_line() == (
        "error: another command moved the arm while this move was checked; nothing moved, "
        "send it again"
    )
    assert mover.ask("where") == f"ok {OTHER}"
