"""``transports.parse_process``: what crosses back is what was sent, taken in a slice at a
time; the child's errors are raised here; a child that dies or hangs costs one job."""

from __future__ import annotations

import asyncio
import operator
import time

import pytest

from c2rviz.transports import parse_process
from c2rviz.transports.parse_process import LONG, ParseProcess, ProcessLost, pack, unpack
from c2rviz.transports.rosbridge.protocol import RosbridgeError


def test_long_lists_and_tuples_cross_in_slices_and_come_back_the_same(monkeypatch) -> None:
    shared = tuple(range(3 * LONG))
    value = {
        "points": [{"positions": [0.5 * i] * 7, "i": i} for i in range(5 * LONG)],
        "again": shared,
        "same": shared,
        "nested": [[j] * (LONG + 1) for j in range(3)],
        "short": (1, 2.5, "three"),
        "error": RosbridgeError("bad frame", id="f1", op="publish"),
    }
    monkeypatch.setattr(parse_process, "UNPACK_TURN_S", 0.0)  # a turn after every slice
    turns = 0

    async def other_client() -> None:
        nonlocal turns
        while True:
            turns += 1
            await asyncio.sleep(0)

    async def main() -> object:
        other = asyncio.ensure_future(other_client())
        try:
            return await unpack(pack(value))
        finally:
            other.cancel()

    back = asyncio.run(main())
    assert isinstance(back, dict)
    error = back.pop("error")
    expected = dict(value)
    expected.pop("error")
    assert back == expected
    assert type(back["again"]) is tuple and back["again"] is back["same"]
    assert isinstance(error, RosbridgeError) and str(error) == "publish: bad frame"
    assert (error.id, error.op, error.problem) == ("f1", "publish", "bad frame")
    assert turns > 5 * LONG // parse_process.SLICE_ITEMS  # the others went between slices


def test_a_job_answers_or_raises_as_called_here() -> None:
    async def main() -> None:
        process = ParseProcess("test parsing")
        try:
            assert await process.run(operator.add, 2, 3) == 5
            with pytest.raises(ValueError, match="invalid literal"):
                await process.run(int, "x")
            assert process.started == 1
        finally:
            await process.close()
        assert process.pid is None

    asyncio.run(main())


def test_a_hung_child_is_killed_at_its_deadline_and_the_next_job_gets_a_new_one() -> None:
    async def main() -> None:
        process = ParseProcess("test parsing", deadline_s=1.0)
        try:
            assert await process.run(operator.add, 1, 1) == 2  # (started: the deadline is
            with pytest.raises(ProcessLost, match="did not answer within 1 s"):  # the job's)
                await process.run(time.sleep, 120)
            assert await process.run(operator.add, 1, 2) == 3
            assert process.started == 2
        finally:
            await process.close()

    asyncio.run(main())


def test_a_job_given_up_by_its_caller_does_not_answer_the_next() -> None:
    """A caller cancelled while its job runs (its client left): the job's answer is read
    and dropped, so the next job hears its own; one still queued is dropped unrun."""

    async def main() -> None:
        process = ParseProcess("test parsing")
        try:
            assert await process.run(operator.add, 0, 0) == 0
            running = asyncio.ensure_future(process.run(time.sleep, 0.5))
            queued = asyncio.ensure_future(process.run(operator.add, 10, 10))
            while not process.busy:
                await asyncio.sleep(0.01)
            running.cancel()
            queued.cancel()
            assert await process.run(operator.add, 2, 2) == 4
            assert running.cancelled() and queued.cancelled()
            assert process.started == 1
        finally:
            await process.close()

    asyncio.run(main())
