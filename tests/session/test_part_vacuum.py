"""A vacuum gripper (ini ``gripper = vacuum``): the tool point is the cup; ``grip 0``
turns suction on and takes a part whose surface is within 3 mm of it, ``grip 1`` lets go."""

from __future__ import annotations

import pytest
from support import ROBOTS, ROOT, Client, ServerLimits, ServerThread

from c2rviz.app.ini_world import gripper_from
from c2rviz.robot.model import Robot
from c2rviz.world.part_rules import is_vacuum, make_vacuum
from c2rviz.world.virtual_clock import VirtualClock


@pytest.fixture
def vacuum():
    path, base, eelink = ROBOTS["motoman_sia20d"]
    robot = Robot.from_urdf(ROOT / path, base, eelink)  # its own: the cached one stays bare
    robot.gripper = make_vacuum(robot.eelink)
    server = ServerThread(robot, ServerLimits(), clock=VirtualClock()).start()
    client = Client(server.host, server.port)
    try:
        yield server, client
    finally:
        client.close()
        server.stop()


def _cup(client: Client) -> list[float]:
    return [float(v) for v in client.ask("pose")[3:].split(",")[:3]]


@pytest.mark.parametrize(("gap_mm", "taken"), [(0.0, True), (2.5, True), (4.0, False)])
def test_suction_takes_a_part_whose_surface_is_at_the_cup(vacuum, gap_mm, taken):
    _, client = vacuum
    assert client.ask("grip") == "ok 1"  # suction off at the start
    x, y, z = _cup(client)
    top = z - gap_mm / 1000  # a ball hanging under the cup... its top gap_mm below it
    assert client.ask(f"part b sphere 0.02 {x},{y},{top - 0.02}") == "ok"
    assert client.ask("grip 0") == ("ok held" if taken else "ok")
    assert client.ask("part b").endswith(" held" if taken else " free")


def test_a_held_part_follows_the_cup_and_falls_when_suction_is_off(vacuum):
    _, client = vacuum
    x, y, z = _cup(client)
    assert client.ask(f"part b sphere 0.02 {x},{y},{z - 0.02}") == "ok"
    assert client.ask("grip 0") == "ok held"
    assert client.ask("joints 0.5,0.3,0,0,0,0,0") == "ok"
    held = [float(v) for v in client.ask("part b").split()[1].split(",")]
    assert held[:3] != pytest.approx([x, y, z - 0.02], abs=0.01)
    assert client.ask("grip 1") == "ok"
    assert client.ask("sleep 2") == "ok"
    assert client.ask("part b").endswith(" resting on floor")


def test_the_ini_says_vacuum() -> None:
    path, base, eelink = ROBOTS["kuka_lwr"]
    robot = Robot.from_urdf(ROOT / path, base, eelink)
    gripper = gripper_from("kuka_lwr", {"gripper": "vacuum"}, robot)
    assert is_vacuum(gripper) and gripper is not None and gripper.name == "lwr_7_link"
