"""The worker: one thread, a bounded queue, latest wins per key, urgent jobs first."""

from __future__ import annotations

import asyncio
import contextlib
import sys
import threading

import pytest

from c2rviz.session.lanes import Superseded, WorkerBusy
from c2rviz.session.worker import SWITCH_S, Worker


def run(coro):  # type: ignore[no-untyped-def]
    return asyncio.run(coro)


def test_jobs_run_one_at_a_time_in_order_off_the_loop() -> None:
    async def main() -> list[str]:
        worker = Worker()
        done: list[str] = []
        loop_thread = threading.get_ident()

        def job(name: str) -> str:
            assert threading.get_ident() != loop_thread
            done.append(name)
            return name

        futures = [worker.run(lambda k=k: job(f"j{k}")) for k in range(5)]
        results = await asyncio.gather(*futures)
        worker.close()
        assert done == results
        return results

    assert run(main()) == ["j0", "j1", "j2", "j3", "j4"]
    assert sys.getswitchinterval() <= SWITCH_S


def test_the_queue_is_bounded_and_an_error_reaches_its_caller() -> None:
    async def main() -> None:
        worker = Worker(max_queue=2)
        gate = threading.Event()
        running = worker.run(gate.wait)
        waiting = [worker.run(lambda: 1), worker.run(lambda: 2)]
        with pytest.raises(WorkerBusy, match=r"^the server is busy: 2 heavy commands"):
            worker.run(lambda: 3)
        urgent = worker.run(lambda: "first", urgent=True)  # urgent jobs go past the bound
        gate.set()
        assert await running is True
        assert await urgent == "first"
        assert await asyncio.gather(*waiting) == [1, 2]

        def boom() -> None:
            raise ValueError("boom")

        with pytest.raises(ValueError, match="boom"):
            await worker.run(boom)
        worker.close()

    run(main())


def test_a_newer_job_with_the_same_key_replaces_the_waiting_one() -> None:
    async def main() -> None:
        worker = Worker()
        gate = threading.Event()
        order: list[str] = []
        blocker = worker.run(gate.wait)
        older = worker.run(lambda: order.append("older"), key="page")
        other = worker.run(lambda: order.append("other"), key="tcp")
        newer = worker.run(lambda: order.append("newer"), key="page")
        urgent = worker.run(lambda: order.append("urgent"), urgent=True)
        gate.set()
        await asyncio.gather(blocker, other, newer, urgent)
        with pytest.raises(Superseded):
            await older
        assert order == ["urgent", "other", "newer"]
        worker.close()

    run(main())


def test_a_cancelled_job_is_skipped_and_close_cancels_the_rest() -> None:
    async def main() -> None:
        worker = Worker()
        gate = threading.Event()
        ran: list[int] = []
        blocker = worker.run(gate.wait)
        gone = worker.run(lambda: ran.append(1))
        gone.cancel()  # its client went away
        kept = worker.run(lambda: ran.append(2))
        gate.set()
        await blocker
        await kept
        assert ran == [2]
        late = worker.run(gate.wait)
        worker.close()
        with contextlib.suppress(asyncio.CancelledError):  # dropped before the thread took it
            assert await late is True  # ... or it had started
        assert worker.run(lambda: 3).cancelled()

    run(main())


def test_a_failed_job_whose_reply_was_cancelled_logs_nothing_at_close() -> None:
    """The executor's exception is read even when nobody awaits the job any more (its
    client went away): asyncio logs no "Future exception was never retrieved"."""
    import gc

    seen: list[dict[str, object]] = []

    async def main() -> None:
        asyncio.get_running_loop().set_exception_handler(lambda _loop, ctx: seen.append(ctx))
        worker = Worker()
        gate = threading.Event()

        def boom() -> None:
            gate.wait()
            raise ValueError("boom after its client left")

        future = worker.run(boom, owner="client")
        await asyncio.sleep(0)
        future.cancel()  # the client closed while it ran
        after = worker.run(lambda: "next")  # the lane's thread is free again after boom
        gate.set()
        assert await after == "next"
        worker.close()
        gc.collect()
        await asyncio.sleep(0)

    run(main())
    gc.collect()
    assert not [ctx for ctx in seen if "never retrieved" in str(ctx.get("message"))], seen
