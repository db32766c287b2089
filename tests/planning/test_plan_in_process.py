"""A plan that searches past its thread's share goes on in a forked child
(``session.plan_process.plan_job``): the same seed finds the same path as one search."""

from __future__ import annotations

import pytest
from planning_scenes import blocked_scenes, load
from support import Client, ServerThread

from c2rviz.collision import CollisionModel
from c2rviz.protocol.replies import numbers
from c2rviz.session import SessionDefaults, plan_process
from c2rviz.session.services import ServerLimits


def test_a_seeded_plan_that_goes_on_in_a_process_finds_the_path_of_one_search(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Its first ``THREAD_S`` on the thread, the rest in a child that searches again from
    the start with the same seed: the path of a single search."""
    robot = load("kuka_lwr")
    (scene,) = blocked_scenes(CollisionModel(robot), 1, seed=5)
    paths = []
    for processes, thread_s in ((False, plan_process.THREAD_S), (True, 1e-4)):
        monkeypatch.setattr(plan_process, "THREAD_S", thread_s)
        server = ServerThread(robot, ServerLimits()).start()
        try:
            server.services.defaults = SessionDefaults(plan_seed=1234)
            server.call(setattr, server.services.worker, "plan_processes", processes)
            client = Client(server.host, server.port)
            for k, (size, centre) in enumerate(scene.boxes):
                line = f"object box{k} box {numbers(size)} {numbers(centre)},0,0,0"
                assert client.ask(line) == "ok"
            assert client.ask(f"j {numbers(scene.start)}") == "ok"
            assert client.ask(f"plan joints {numbers(scene.goal)}").startswith("ok ")
            paths.append(client.ask("plan"))
            client.close()
        finally:
            server.stop()
    assert paths[0] == paths[1] and paths[0].count(";") >= 2
