"""A frame of more robots than one turn of the loop samples (``moves.TICK_ROBOTS``): every
robot is still sampled every frame, and every move arrives where it was sent."""

from __future__ import annotations

import asyncio
import inspect
from collections import Counter
from dataclasses import dataclass, field

import numpy as np
import pytest
from support import load_robot

from c2rviz.session import Services
from c2rviz.session.session import Session
from c2rviz.world import moves
from c2rviz.world.observer import RecordingScene
from c2rviz.world.world import World


@dataclass
class Frames(RecordingScene):
    """Counts the frames published per robot."""

    per_robot: Counter[str] = field(default_factory=Counter)

    def on_joints(self, robot: str, q: object, t: float) -> None:
        self.per_robot[robot] += 1
        super().on_joints(robot, q, t)  # type: ignore[arg-type]


def test_robots_sampled_one_per_turn_all_arrive_every_frame_drawn(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setattr(moves, "TICK_ROBOTS", 1)
    names = ["a", "b", "c"]
    scene = Frames()

    async def drive() -> list[str]:
        world = World({name: load_robot() for name in names}, scene)
        services = Services(world)
        replies = []
        for k, name in enumerate(names):
            session = Session(services, "test", name)
            for line in ("degrees", "motion on", "speed 100"):
                session.run(line)
            reply = session.run(f"j {10 * (k + 1)},0,0,0,0,0,0")
            replies.append(await reply if inspect.isawaitable(reply) else reply)
        return [str(r) for r in replies] + [str(world.state(n).q[0]) for n in names]

    out = asyncio.run(asyncio.wait_for(drive(), 120))
    assert out[:3] == ["ok"] * 3
    assert [float(v) for v in out[3:]] == pytest.approx(np.radians([10.0, 20.0, 30.0]))
    # each robot's move lasts many frames, and the last was sampled in each of them
    assert all(scene.per_robot[name] > 5 for name in names), scene.per_robot
