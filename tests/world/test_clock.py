"""The clocks: ``--clock`` forms, scaled time, and virtual time's holds and jumps.

The virtual clock is driven on a real asyncio loop: timers fire in clock order, time
stands still while a hold is taken, a reply that waits on the clock releases its
client's hold and takes it back the instant it is settled.
"""

from __future__ import annotations

import asyncio
import time

import pytest
from support import ROOT, Client, ServerThread, load_robot

from c2rviz.app.config import load_settings
from c2rviz.errors import ConfigError
from c2rviz.session import ServerLimits
from c2rviz.world.clock import NO_HOLD, Clock, ScaledClock
from c2rviz.world.virtual_clock import CLOCK_FORMS, VirtualClock, parse_clock


@pytest.mark.parametrize(
    ("text", "kind", "described"),
    [
        ("real", Clock, "real"),
        ("REAL", Clock, "real"),
        ("scaled:10", ScaledClock, "scaled:10"),
        ("scaled:0.5", ScaledClock, "scaled:0.5"),
        ("virtual", VirtualClock, "virtual"),
    ],
    ids=["real", "upper-case", "scaled-10", "scaled-half", "virtual"],
)
def test_good_clock_forms(text, kind, described):
    clock = parse_clock(text)
    assert type(clock) is kind and clock.describe() == described


@pytest.mark.parametrize(
    "text",
    ["scaled:0", "scaled:-2", "scaled:nan", "scaled:inf", "scaled:", "scaled:x", "fast", ""],
    ids=["zero", "negative", "nan", "inf", "empty-factor", "word-factor", "unknown", "empty"],
)
def test_bad_clock_forms_name_the_valid_ones(text):
    with pytest.raises(ConfigError) as caught:
        parse_clock(text)
    assert all(form in str(caught.value) for form in CLOCK_FORMS)


def test_scaled_time_runs_faster():
    """50 x: the clock's span is fifty times the wall's, read just inside and just outside
    it, whatever the machine's load; and its timers fire on the clock."""
    clock = ScaledClock(50.0)
    outer_start = time.monotonic()
    start = clock.now()
    inner_start = time.monotonic()

    async def sleep_one_clock_second() -> tuple[float, float, float]:
        loop = asyncio.get_running_loop()
        done = loop.create_future()
        clock.call_later(1.0, done.set_result, None)
        await done
        return time.monotonic(), clock.now(), time.monotonic()

    inner_end, end, outer_end = asyncio.run(sleep_one_clock_second())
    clock_s = end - start
    assert clock_s >= 1.0 - 1e-6
    assert (
        50.0 * (inner_end - inner_start) - 1e-6
        <= clock_s
        <= 50.0 * (outer_end - outer_start) + 1e-6
    )


def test_real_and_scaled_clocks_hold_nothing():
    assert Clock().hold() is NO_HOLD and ScaledClock(2).hold() is NO_HOLD


def test_virtual_time_jumps_through_timers_in_order():
    clock = VirtualClock()
    fired: list[tuple[str, float]] = []

    async def main() -> None:
        done = asyncio.get_running_loop().create_future()
        clock.call_at(30.0, fired.append, ("c", 30.0))
        clock.call_at(10.0, fired.append, ("a", 10.0))
        clock.call_at(10.0, fired.append, ("b", 10.0))  # same time: in the order set
        cancelled = clock.call_at(20.0, fired.append, ("never", 20.0))
        cancelled.cancel()
        clock.call_at(3600.0, done.set_result, None)
        await done

    asyncio.run(main())  # an hour of the clock, which on the real one outlasts the time limit
    assert fired == [("a", 10.0), ("b", 10.0), ("c", 30.0)]
    assert clock.now() == 3600.0  # how fast: benchmarks/testing_bench.py


def test_a_hold_stops_time_until_released():
    clock = VirtualClock()

    async def main() -> tuple[float, float]:
        hold = clock.hold()
        fired = asyncio.get_running_loop().create_future()
        clock.call_later(5.0, fired.set_result, None)
        for _ in range(20):  # many loop turns: time stands still while the hold is taken
            await asyncio.sleep(0)
        held_at = clock.now()
        hold.release()
        await fired
        return held_at, clock.now()

    assert asyncio.run(main()) == (0.0, 5.0)


def test_due_timers_run_while_held():
    clock = VirtualClock()

    async def main() -> bool:
        clock.hold()  # held for good
        done = asyncio.get_running_loop().create_future()
        clock.call_later(0.0, done.set_result, True)
        return await asyncio.wait_for(done, 5.0)

    assert asyncio.run(main())


def test_a_wait_releases_the_acting_hold_and_settling_takes_it_back_at_once():
    """Two clients: A sleeps 1 s, B sleeps 2 s. When A's sleep ends, A is busy again
    before anything else runs, so B's timer cannot fire until A says it waits again."""
    clock = VirtualClock()
    log: list[tuple[str, float]] = []

    def sleep(hold, seconds: float) -> asyncio.Future[None]:
        with hold.acting():
            future = clock.future()  # releases `hold` until it is settled
        clock.call_later(seconds, future.set_result, None)
        return future

    async def client(name: str, hold, seconds: float, thinking_turns: int) -> None:
        await sleep(hold, seconds)
        log.append((name, clock.now()))
        for _ in range(thinking_turns):  # busy (held) for a while after waking
            await asyncio.sleep(0)
        log.append((name + " thought", clock.now()))
        hold.close()

    async def main() -> None:
        a, b = clock.hold(), clock.hold()
        await asyncio.gather(client("a", a, 1.0, 50), client("b", b, 2.0, 0))

    asyncio.run(main())
    assert log == [("a", 1.0), ("a thought", 1.0), ("b", 2.0), ("b thought", 2.0)]


def test_the_ini_names_the_clock_and_a_bad_one_names_the_key(tmp_path):
    urdf = {"urdf": ROOT / "robots" / "kuka_lwr" / "robot.urdf"}
    good = tmp_path / "good.ini"
    good.write_text("[options]\nclock = virtual\n")
    assert load_settings(good, urdf).clock == "virtual"
    assert load_settings(good, {**urdf, "clock": "scaled:3"}).clock == "scaled:3"  # flag wins
    bad = tmp_path / "bad.ini"
    bad.write_text("[options]\nclock = scaled:-1\n")
    with pytest.raises(ConfigError, match=r"\[options\] clock scaled:-1: the factor"):
        load_settings(bad, urdf)


def test_a_scaled_clock_runs_motion_faster_and_the_world_stamps_its_time():
    """What the page and every observer are told follows the clock: a move of some
    seconds of the clock is shown over that many clock seconds, stamped by the clock.

    Judged on the clock, not the wall: how often a busy machine's timers let frames come
    (about every 1 ms of the wall when quiet) is a figure, not a behaviour."""
    clock = ScaledClock(20.0)
    server = ServerThread(load_robot(), ServerLimits(), clock=clock).start()
    try:
        client = Client(server.host, server.port)
        assert client.ask("motion on") == "ok"
        assert client.ask("speed 20") == "ok"
        wall_before, before = time.monotonic(), clock.now()
        assert client.ask("joints 1,0.5,0,-0.5,0,0.5,0") == "ok"  # on arrival
        after, wall_after = clock.now(), time.monotonic()
        client.close()
        times = server.scene.times
        shown = times[-1] - times[0]
        assert shown > 5.0  # the move takes seconds of the clock...
        assert before <= times[0] and times[-1] <= after  # ...stamped by the scaled clock...
        assert after - before <= 20.0 * (wall_after - wall_before) + 1e-6  # ...20 x the wall
        assert len(times) > 2 and all(b > a for a, b in zip(times, times[1:]))
    finally:
        server.stop()


def test_a_timed_future_outside_any_hold_is_a_plain_one_and_cancelling_one_ends_its_wait():
    clock = VirtualClock()

    async def main() -> tuple[bool, int]:
        plain = clock.future()  # no acting hold: nobody's reply
        hold = clock.hold()
        with hold.acting():
            waiting = clock.future()
        released = clock.busy_count
        waiting.cancel()  # its client left
        return type(plain) is asyncio.Future and released == 0, clock.busy_count

    assert asyncio.run(main()) == (True, 1)


LATE_S = 0.01
"""How late every timer of ``LateClock`` fires [s]: a busy machine's loop, within the
session's cadence window (``session._CADENCE_S``, 20 ms)."""


class LateClock(VirtualClock):
    """Virtual time whose every timer fires ``LATE_S`` late, as a busy machine's loop does:
    lateness made exact, so what it adds up to is a fact, not a figure of the wall."""

    def call_at(self, when, fn, *args):  # type: ignore[no-untyped-def]
        return super().call_at(when + LATE_S, fn, *args)


def test_consecutive_sleeps_keep_the_cadence_when_timers_fire_late():
    """A played script's sleeps, each timer late: the lateness does not add up (a replay
    of a recording keeps its cadence: tests/observers/test_record.py plays one)."""
    clock = LateClock()
    server = ServerThread(load_robot(), ServerLimits(), clock=clock).start()
    client = Client(server.host, server.port)
    try:
        start = server.call(clock.now)
        client.send("sleep 0.1\n" * 20)
        assert [client.read_line() for _ in range(20)] == ["ok"] * 20
        # One timer's lateness at the end, not twenty (2.2 s if each sleep counted from
        # its late start).
        assert server.call(clock.now) - start == pytest.approx(2.0 + LATE_S, abs=1e-9)
    finally:
        client.close()
        server.stop()
