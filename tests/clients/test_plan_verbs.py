"""The clients' planning, guard-mode, gripper and ghost methods against a real server."""

from __future__ import annotations

import asyncio

import pytest

from c2rviz import AsyncClient, Client, CommandError
from c2rviz.clients.errors import ArgumentError
from c2rviz.clients.task_calls import PlanSummary


def test_planning_around_an_object_through_the_client(server) -> None:
    with Client(server.host, server.port) as robot:
        robot.add_object("post", "box", [0.2, 0.2, 0.2], [0, 0.8, 0.85, 0, 0, 0])
        assert robot.plan_timeout() == 1.0
        assert robot.plan_timeout(3) == 3.0 and robot.plan_timeout() == 3.0
        assert robot.plan_resolution((0.02, 0.004)) == (0.02, 0.004)
        assert robot.plan_resolution() == (0.02, 0.004)
        goal = (0.5, 0.3, 0.0, -0.4, 0.0, 0.3, 0.0)
        summary = robot.plan_joints(goal)
        assert isinstance(summary, PlanSummary) and summary.unit == "rad"
        assert summary.waypoints >= 2 and summary.length > 0 and summary.duration > 0
        path = robot.plan()
        assert len(path) == summary.waypoints
        assert path[-1] == pytest.approx(goal) and robot.where() == pytest.approx(goal)
        assert robot.plan_pose(robot.pose()[:3]).waypoints >= 2
        with pytest.raises(ArgumentError, match="plan_joints"):
            robot.plan_joints([0.1, 0.2])  # the robot has 7 joints: nothing sent
        with pytest.raises(CommandError, match="give a number from 0.001 to 60 s"):
            robot.plan_timeout(-1)
        assert robot.plan_timeout() == 3.0


def test_guard_modes_ghost_and_a_missing_gripper(server) -> None:
    with Client(server.host, server.port) as robot:
        assert robot.guard_mode() == "off" and robot.guard() is False
        assert robot.guard_mode("plan") == "plan"
        assert robot.guard_mode() == "plan" and robot.guard() is True  # on, and planning
        assert robot.ghost() is True and robot.ghost(False) is False and robot.ghost() is False
        with pytest.raises(CommandError, match="no gripper"):
            robot.grip(1)
        with pytest.raises(ArgumentError, match="guard_mode"):
            robot.guard_mode("sometimes")


def test_the_gripper_through_the_async_client(start_server) -> None:
    server = start_server("fanuc_lrmate200id")

    async def run() -> tuple[float, float]:
        async with AsyncClient(server.host, server.port) as robot:
            await robot.grip(0.75)
            return await robot.grip(), await robot.plan_timeout()

    assert asyncio.run(run()) == (0.75, 1.0)
