"""Heavy work scheduled fairly (issue 35, Build 2): owners served in turn, a plan lane, and
plans cancelled by ``stop``, by their client closing and by a newer plan.

The scheduler is driven with fake jobs (a gate holds a lane's thread), the plans with
real OMPL searches into a chimney that has no way in; every check is on the order of
events (which job ran first, which reply came while which job still ran, why a plan
stopped), never on how long anything took.
"""

from __future__ import annotations

import asyncio
import threading
from collections.abc import Callable

import pytest
from support import Client, ServerThread

from c2rviz.errors import C2rvizError
from c2rviz.planning.errors import STOPPED, SUPERSEDED, WENT_AWAY, Cancel, PlanCancelled
from c2rviz.session import Session
from c2rviz.session.lanes import Superseded, WorkerBusy
from c2rviz.session.worker import MAX_PER_OWNER, Worker

GOAL = "0,90,0,0,0,0,0"  # [deg] the arm lying along +x: inside the chimney
HALF, WALL, Z = 0.16, 0.02, 0.41  # [m] the chimney's inner half width, its walls, its axis
CHIMNEY = [  # a capped square tube around the arm's goal, open towards the arm: no way in
    f"object top box 1.1,{2 * HALF + 2 * WALL},{WALL} 0.85,0,{Z + HALF + WALL / 2},0,0,0",
    f"object bottom box 1.1,{2 * HALF + 2 * WALL},{WALL} 0.85,0,{Z - HALF - WALL / 2},0,0,0",
    f"object left box 1.1,{WALL},{2 * HALF} 0.85,{HALF + WALL / 2},{Z},0,0,0",
    f"object right box 1.1,{WALL},{2 * HALF} 0.85,{-HALF - WALL / 2},{Z},0,0,0",
    f"object cap box {WALL},{2 * HALF + 2 * WALL},{2 * HALF + 2 * WALL} 1.41,0,{Z},0,0,0",
]


def run(coro):  # type: ignore[no-untyped-def]
    return asyncio.run(coro)


# The scheduler, with fake jobs.


def test_owners_are_served_in_turn() -> None:
    async def main() -> list[str]:
        worker = Worker()
        gate = threading.Event()
        order: list[str] = []
        blocker = worker.run(gate.wait)
        jobs = [
            worker.run(lambda name=name: order.append(name), owner=owner)
            for name, owner in [
                ("a1", "a"),
                ("a2", "a"),
                ("a3", "a"),
                ("b1", "b"),
                ("c1", "c"),
                ("c2", "c"),
            ]
        ]
        gate.set()
        await asyncio.gather(blocker, *jobs)
        worker.close()
        return order

    assert run(main()) == ["a1", "b1", "c1", "a2", "c2", "a3"]


def test_a_newer_job_with_the_same_key_replaces_only_that_owners_waiting_one() -> None:
    async def main() -> None:
        worker = Worker()
        gate = threading.Event()
        order: list[str] = []
        blocker = worker.run(gate.wait)
        older = worker.run(lambda: order.append("a old"), key=("move", "a"), owner="a")
        other = worker.run(lambda: order.append("b"), key=("move", "b"), owner="b")
        newer = worker.run(lambda: order.append("a new"), key=("move", "a"), owner="a")
        gate.set()
        await asyncio.gather(blocker, other, newer)
        with pytest.raises(Superseded):
            await older
        assert order == ["b", "a new"]
        worker.close()

    run(main())


def test_each_owner_and_the_lane_are_bounded() -> None:
    async def main() -> None:
        worker = Worker(max_queue=MAX_PER_OWNER + 2)
        gate = threading.Event()
        blocker = worker.run(gate.wait)
        mine = [worker.run(lambda: None, owner="a") for _ in range(MAX_PER_OWNER)]
        with pytest.raises(WorkerBusy, match=r"this connection has \d+ heavy commands"):
            worker.run(lambda: None, owner="a")
        others = [worker.run(lambda: None, owner=owner) for owner in ("b", "c")]
        with pytest.raises(WorkerBusy, match=rf"^the server is busy: {MAX_PER_OWNER + 2} heavy"):
            worker.run(lambda: None, owner="d")
        gate.set()
        await asyncio.gather(blocker, *mine, *others)
        worker.close()

    run(main())


def test_a_plan_holds_no_work_behind_it() -> None:
    async def main() -> None:
        worker = Worker(plan_processes=False)
        gate = threading.Event()
        plan = worker.plan(gate.wait, owner="a")
        assert await worker.run(lambda: "ik", owner="b") == "ik"
        assert await worker.run(lambda: "own ik", owner="a") == "own ik"
        assert not plan.done() and not gate.is_set()  # ... answered while the plan ran
        gate.set()
        assert await plan is True
        worker.close()

    run(main())


def test_plans_of_several_owners_run_side_by_side_one_per_owner() -> None:
    async def main() -> None:
        worker = Worker(plan_threads=3, plan_processes=False)
        started = {name: threading.Event() for name in ("a1", "a2", "b1", "c1")}
        gate = threading.Event()

        def plan(name: str) -> str:
            started[name].set()
            gate.wait(60)
            return name

        jobs = [
            worker.plan(lambda name=name: plan(name), owner=name[0])
            for name in ("a1", "a2", "b1", "c1")
        ]
        for name in ("a1", "b1", "c1"):  # three owners: three plans at once
            assert await asyncio.to_thread(started[name].wait, 60)
        assert not started["a2"].is_set()  # a's second waits for its first
        gate.set()
        assert await asyncio.gather(*jobs) == ["a1", "a2", "b1", "c1"]
        worker.close()

    run(main())


def test_cancel_stops_an_owners_running_and_waiting_plans() -> None:
    async def main() -> None:
        worker = Worker(plan_processes=False)
        running, waiting, others = Cancel(), Cancel(), Cancel()

        def search(cancel: Cancel) -> str:
            for _ in range(60_000):  # a search that looks at its flag
                if cancel():
                    cancel.check()
                threading.Event().wait(0.001)
            return "found"

        first = worker.plan(lambda: search(running), owner="a", cancel=running)
        second = worker.plan(lambda: search(waiting), owner="a", cancel=waiting)
        other = worker.plan(lambda: search(others), owner="b", cancel=others)
        assert worker.cancel("a", STOPPED) == 2
        for job in (first, second):
            with pytest.raises(PlanCancelled, match=r"^plan cancelled \(stopped\); nothing moved"):
                await job
        assert not others()
        others.set(WENT_AWAY)
        with pytest.raises(PlanCancelled):
            await other
        worker.close()

    run(main())


def test_a_plans_cancel_is_set_when_its_awaiting_reply_is_cancelled() -> None:
    async def main() -> None:
        worker = Worker(plan_processes=False)
        cancel = Cancel()
        started = threading.Event()

        def search() -> None:
            started.set()
            while not cancel():
                threading.Event().wait(0.001)
            cancel.check()

        job = worker.plan(search, owner="a", cancel=cancel)
        assert await asyncio.to_thread(started.wait, 60)
        job.cancel()  # its client closed: the connection cancels its reply
        for _ in range(60_000):
            if not worker.plans.running:
                break
            await asyncio.sleep(0.001)
        assert cancel() and cancel.why == WENT_AWAY and not worker.plans.running
        worker.close()

    run(main())


# Real plans, through the server.


@pytest.fixture
def chimney(server: ServerThread, connect) -> Callable[..., Client]:
    """Clients of a server whose arm's goal ``GOAL`` lies in a chimney (guard on)."""
    builder = connect(server)
    for line in CHIMNEY:
        assert builder.ask(line) == "ok", line

    def open_client(*lines: str) -> Client:
        opened = connect(server)
        for line in ("degrees", "guard on", *lines):
            assert opened.ask(line) == "ok", line
        return opened

    return open_client


def running_plans(server: ServerThread) -> list:
    return server.call(lambda: list(server.services.worker.plans.running))


def wait_for_plans(server: ServerThread, count: int) -> list:
    for _ in range(100_000):
        plans = running_plans(server)
        if len(plans) >= count:
            return plans
    raise AssertionError(f"never {count} plans searching")


def test_a_bystanders_ik_is_answered_while_a_plan_searches(server: ServerThread, chimney):
    planner, bystander = chimney("plan timeout 60"), chimney()
    planner.send(f"plan joints {GOAL}\n")
    (plan,) = wait_for_plans(server, 1)
    pose = bystander.ask("pose")[3:]
    assert bystander.ask(f"ik {pose}").startswith("ok ")
    assert bystander.ask("joints 5,0,0,0,0,0,0") == "ok"  # guarded, checked meanwhile
    assert running_plans(server) == [plan]  # ... while the plan still searched
    planner.close()


def test_a_plan_whose_reply_is_cancelled_stops_searching(server: ServerThread, chimney):
    """What a connection that closes does to the reply it owes (``pending.cancel()``)."""
    chimney()  # the chimney built

    async def plan_then_leave() -> tuple[bool, str, int]:
        session = Session(server.services, source="page")
        for line in ("degrees", "guard on", "plan timeout 60"):
            assert session.run(line) == "ok"
        reply = asyncio.ensure_future(session.run(f"plan joints {GOAL}"))  # type: ignore[arg-type]
        plans = server.services.worker.plans
        while not plans.running:
            await asyncio.sleep(0.001)
        (job,) = plans.running
        reply.cancel()
        while plans.running:
            await asyncio.sleep(0.001)
        return job.cancel(), job.cancel.why, len(plans.running)

    assert server.call_async(plan_then_leave()) == (True, WENT_AWAY, 0)


def test_stop_and_a_newer_plan_cancel_a_plan(server: ServerThread, chimney):
    chimney()  # the chimney built

    async def plans() -> list[object]:
        session = Session(server.services, source="page")
        for line in ("degrees", "guard on", "plan timeout 60"):
            assert session.run(line) == "ok"
        older = asyncio.ensure_future(session.run(f"plan joints {GOAL}"))  # type: ignore[arg-type]
        while not server.services.worker.plans.running:
            await asyncio.sleep(0.001)
        newer = asyncio.ensure_future(session.run(f"plan joints {GOAL}"))  # type: ignore[arg-type]
        await asyncio.wait([older])
        while not server.services.worker.plans.running:  # the newer one searches now
            await asyncio.sleep(0.001)
        assert session.run("stop") == "ok"
        return list(await asyncio.gather(older, newer, return_exceptions=True))

    older, newer = server.call_async(plans())
    assert (
        isinstance(older, C2rvizError)
        and str(older) == f"plan cancelled ({SUPERSEDED}); nothing moved"
    )
    assert (
        isinstance(newer, C2rvizError)
        and str(newer) == f"plan cancelled ({STOPPED}); nothing moved"
    )
    assert server.q == (0.0,) * 7


def test_a_stop_sent_behind_a_plan_cancels_it_at_once(server: ServerThread, chimney):
    """The text port reads on behind a plan's reply: the ``stop`` the client sent after its
    ``plan`` stops the search now (not after its 15 s), and still answers in its turn."""
    planner = chimney("plan timeout 15")
    planner.send(f"plan joints {GOAL}\n")
    (plan,) = wait_for_plans(server, 1)
    planner.send("stop\nwhere\n")
    assert planner.read_line() == f"error: plan cancelled ({STOPPED}); nothing moved"
    assert planner.read_line() == "ok"  # the stop, in its turn
    assert planner.read_line() == "ok 0,0,0,0,0,0,0"  # nothing moved
    assert plan.cancel() and plan.cancel.why == STOPPED
    assert planner.ask("plan timeout 0.2") == "ok"  # after the stop's turn, plans run again
    reply = planner.ask(f"plan joints {GOAL}")
    assert reply.startswith("error: ") and "cancelled" not in reply  # its own search's end


def test_a_stop_in_the_same_read_as_its_plan_cancels_it(server: ServerThread, chimney):
    planner = chimney("plan timeout 15")
    planner.send(f"plan joints {GOAL}\nstop\n")
    assert planner.read_line() == f"error: plan cancelled ({STOPPED}); nothing moved"
    assert planner.read_line() == "ok"


def test_a_stop_behind_a_sleep_or_an_arrival_waits_its_turn(server: ServerThread, connect):
    """Read ahead, a ``stop`` cuts short only plans: a ``sleep`` or a move's arrival
    ahead of it answers as before, then the ``stop``."""
    client = connect(server)
    assert client.ask("motion on") == "ok"
    client.send("sleep 0.2\nstop\njoints 0.2,0,0,0,0,0,0\nstop\nwhere\n")
    replies = [client.read_line() for _ in range(5)]
    assert replies == ["ok", "ok", "ok", "ok", "ok 0.2,0,0,0,0,0,0"]


def test_a_closed_connections_plan_frees_the_plan_lane(server: ServerThread, chimney):
    """The text port sees a client close behind its plan's reply: the plan stops, and the
    lane (one thread here) serves the next client's plan."""
    server.call(lambda: setattr(server.services.worker.plans, "threads", 1))
    planner, other = chimney("plan timeout 15"), chimney("plan timeout 0.2")
    planner.send(f"plan joints {GOAL}\n")
    (plan,) = wait_for_plans(server, 1)
    planner.close()
    reply = other.ask(f"plan joints {GOAL}")  # waits for the lane's one thread
    assert plan.cancel() and plan.cancel.why == WENT_AWAY
    assert reply.startswith("error: ") and "cancelled" not in reply  # its own search's end


def test_plan_shows_the_path_of_the_last_guard_plan_move(server: ServerThread, connect):
    client = connect(server)
    for line in ("degrees", "guard plan", "motion on", "speed 100"):
        assert client.ask(line) == "ok", line
    assert client.ask("plan") == "ok none"
    assert client.ask("joints 10,0,0,0,0,0,0") == "ok"
    assert client.ask("plan") == "ok 0,0,0,0,0,0,0;10,0,0,0,0,0,0"
