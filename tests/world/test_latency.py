"""``world/clock``: replies late on the world's clock (virtual here), ok and error alike,
and a door's unasked messages late in the order they were made."""

from __future__ import annotations

import asyncio

import pytest

from c2rviz.errors import C2rvizError
from c2rviz.world.clock import LateSends, late
from c2rviz.world.virtual_clock import VirtualClock


def test_sends_keep_their_order_whatever_the_delays_drew() -> None:
    async def run() -> list[tuple[str, float]]:
        clock = VirtualClock()
        delays = iter([0.3, 0.1, 0.0, 0.2, 0.0])
        sent: list[tuple[str, float]] = []
        sends = LateSends(lambda m: sent.append((m, clock.now())), lambda: next(delays), clock)
        for message in "abc":
            sends.send(message)
        await asyncio.sleep(0)
        while sends.waiting:
            await asyncio.sleep(0)
        sends.send("d")  # nothing waits: 0.2 late
        sends.send("e")  # no delay, but after d
        while sends.waiting:
            await asyncio.sleep(0)
        return sent

    sent = asyncio.run(run())
    assert [m for m, _ in sent] == list("abcde")
    assert [t for _, t in sent] == pytest.approx([0.3, 0.3, 0.3, 0.5, 0.5])


def test_a_closed_sender_sends_nothing_more_and_no_delay_sends_at_once() -> None:
    async def run() -> tuple[list[str], list[str]]:
        clock = VirtualClock()
        sent: list[str] = []
        sends = LateSends(sent.append, lambda: 0.5, clock)
        sends.send("late")
        sends.close()
        await asyncio.sleep(0)
        at_once: list[str] = []
        LateSends(at_once.append, lambda: 0.0, clock).send("now")
        return sent, at_once

    assert asyncio.run(run()) == ([], ["now"])


def test_late_replies_errors_alike_and_after_a_reply_that_waits() -> None:
    async def run() -> list[tuple[str, float]]:
        clock = VirtualClock()
        out: list[tuple[str, float]] = []
        for reply in ["ok", C2rvizError("no")]:
            try:
                out.append((await late(reply, 0.25, clock), clock.now()))
            except C2rvizError as error:
                out.append((f"error: {error}", clock.now()))

        async def arrival() -> str:
            waited: asyncio.Future[str] = clock.future()
            clock.call_later(1.0, waited.set_exception, C2rvizError("stalled"))
            return await waited

        try:
            await late(arrival(), 0.25, clock)
        except C2rvizError as error:
            out.append((f"error: {error}", clock.now()))
        return out

    assert asyncio.run(run()) == [("ok", 0.25), ("error: no", 0.5), ("error: stalled", 1.75)]
