"""A connection's status parts: built again only when what they show changed, and the
document written from kept texts is the codec's own, byte for byte."""

from __future__ import annotations

import asyncio

import pytest
from support import load_robot

from c2rviz.session import Services
from c2rviz.session.session import Session
from c2rviz.transports.crcl import write_status
from c2rviz.transports.crcl.actions import ACTIONS
from c2rviz.transports.crcl.controller import Controller, Report
from c2rviz.world.world import World


def test_kept_parts_write_what_the_codec_writes() -> None:
    async def run() -> None:
        world = World(load_robot("fanuc_lrmate200id"))
        services = Services(world)
        controller = Controller(Session(services, "crcl test"), lambda doc: None, ACTIONS)
        parts = controller.parts
        report = Report(3, "MoveToType (CommandID 3)", "CRCL_Done", "a < b & c")
        first = controller.status(report, full=True)
        assert parts.write(first) == write_status(first)
        again = controller.status(report, full=True)
        assert again.settings_status is first.settings_status  # kept: nothing changed
        assert again.pose_status is first.pose_status
        assert parts.write(again) == write_status(again)
        world.set_q((0.1, 0.2, 0.3, 0.0, 0.5, 0.0))
        world.grips.set(world.state(), 0.5, "test")
        controller.settings.length_unit = "inch"
        controller.settings.revision += 1
        moved = controller.status(report, full=True)
        assert moved.pose_status is not first.pose_status
        assert moved.settings_status.length_unit == "inch"
        assert moved.gripper_status.separation == pytest.approx(0.03 / 0.0254)
        assert parts.write(moved) == write_status(moved)
        compact = controller.status(report, full=False)
        assert parts.write(compact) == write_status(compact)
        services.close()

    asyncio.run(run())
