"""WatchHub listeners: watch's event texts for consumers without a socket (rosbridge)."""

from __future__ import annotations

import asyncio

import pinocchio as pin
from support import load_robot

from c2rviz.observers.watch import WatchHub
from c2rviz.world.world import World


def test_a_listener_gets_every_event_text_and_costs_nothing_once_gone() -> None:
    async def scenario() -> None:
        world = World(load_robot("motoman_sia20d"))
        hub = WatchHub(world)
        heard: list[tuple[str | None, str]] = []

        def listener(robot: str | None, text: str) -> None:
            heard.append((robot, text))

        assert hub not in world.observers  # nobody watches or listens: no cost
        hub.listen(listener)
        assert hub in world.observers
        placement = pin.SE3(pin.rpy.rpyToMatrix(0.0, 0.0, 0.5), pin.SE3.Identity().translation)
        placement.translation[:] = (0.5, 0.1, 0.6)
        world.add_marker(placement, (0.0, 1.0, 0.0), "cube")
        world.clear_markers()
        hub.event("record-stopped run: the disk is full")
        assert heard == [
            ("motoman_sia20d", "marker 0.5,0.1,0.6,0,0,0.5 cube 0,1,0"),  # radians
            ("motoman_sia20d", "clear"),
            (None, "record-stopped run: the disk is full"),
        ]
        hub.unlisten(listener)
        hub.unlisten(listener)  # idempotent
        assert hub not in world.observers
        world.clear_markers()
        assert len(heard) == 3
        world.close()

    asyncio.run(scenario())
