"""The client's fault methods: their lines, their readings, arguments refused before
anything is sent."""

from __future__ import annotations

import asyncio

import pytest

from c2rviz import AsyncClient, CommandError
from c2rviz.clients.errors import ArgumentError
from c2rviz.clients.task_calls import clear_faults, fault, read_faults
from c2rviz.errors import C2rvizError
from c2rviz.testing.server import TestServer


@pytest.mark.parametrize(
    ("args", "line"),
    [
        (("estop", (), None, None), "fault estop"),
        (("stall", ("joint_l",), None, None), "fault stall joint_l"),
        (("stall", (3,), None, None), "fault stall 3.0"),
        (("noise", (0.01,), None, None), "fault noise 0.01"),
        (("latency", (50, 10), None, None), "fault latency 50.0,10.0"),
        (("protective", (), 2.5, None), "fault at 2.5 protective"),
        (("estop", (), None, 1), "fault after 1.0 estop"),
    ],
)
def test_fault_lines(args, line):
    assert fault(*args).line == line


@pytest.mark.parametrize(
    ("args", "problem"),
    [
        (("bogus", (), None, None), "'bogus' is not one of estop, protective"),
        (("noise", (-1,), None, None), "noise SIGMA -1 is outside"),
        (("estop", (), None, -1), "S '-1.0' is not a time"),
        (("estop", (), "soon", None), "expected a number"),
    ],
)
def test_bad_fault_arguments_are_refused_before_sending(args, problem):
    with pytest.raises(ArgumentError, match=problem):
        fault(*args)


def test_reading_the_list():
    assert read_faults("ok none") == []
    assert read_faults("ok estop since 1.500; noise 0.01 at 5.000") == [
        "estop since 1.500",
        "noise 0.01 at 5.000",
    ]
    assert clear_faults("all").line == "fault clear all"


@pytest.mark.c2rviz(clock="virtual", motion="on")
def test_the_client_drives_faults(c2rviz):
    c2rviz.fault("estop", after=0.5)
    with pytest.raises(CommandError, match="emergency stop since t="):
        c2rviz.joints([1, 0.5, 0.3, -0.5, 0.2, 0.5, 0.1])
    assert c2rviz.faults()[0].startswith("estop since")
    c2rviz.clear_faults("estop")
    c2rviz.reset()
    c2rviz.fault("stall", "joint_l")
    c2rviz.fault("latency", 5, 1)
    assert [item.split(" since")[0] for item in c2rviz.faults()] == [
        "stall joint_l",
        "latency 5,1",
    ]
    c2rviz.clear_faults()
    assert c2rviz.faults() == []


def test_the_async_client_drives_faults(c2rviz_server):
    async def main() -> list[str]:
        async with AsyncClient(c2rviz_server.host, c2rviz_server.port) as robot:
            await robot.fault("noise", 0.01)
            listed = await robot.faults()
            await robot.clear_faults("noise")
            await robot.reset()
            return listed + await robot.faults()

    listed = asyncio.run(main())
    assert len(listed) == 1 and listed[0].startswith("noise 0.01 since ")


@pytest.mark.c2rviz(clock="virtual", motion="on", faults=["after 0.5 protective"])
def test_the_marker_schedules_faults(c2rviz):
    with pytest.raises(CommandError, match="protective stop since t=0.500"):
        c2rviz.joints([1, 0.5, 0.3, -0.5, 0.2, 0.5, 0.1])
    c2rviz.reset()
    c2rviz.home()


@pytest.mark.c2rviz(clock="virtual", faults=["after 6 protective"])
def test_a_marker_fault_counts_from_the_test_not_the_server(c2rviz_server, c2rviz):
    # The server's clock stands still from its start until the test's client is served:
    # else nothing holds virtual time and the fault is due before the test's first line.
    assert c2rviz_server.now() < 6.0
    assert c2rviz.faults()[0].startswith("protective at 6")
    c2rviz.sleep(5)
    assert c2rviz.faults()[0].startswith("protective at 6")  # still ahead, 5 s in
    c2rviz.sleep(2)
    assert c2rviz.faults()[0].startswith("protective since 6")


def test_a_bad_marker_fault_stops_the_start():
    with pytest.raises(C2rvizError, match="unknown fault 'bogus'"):
        TestServer({"faults": ["bogus"], "record": False}).start()
