"""The page's workcell objects, red collisions and trails, on a real ``ViserScene``."""

from __future__ import annotations

import asyncio
from collections.abc import Iterator
from typing import Any

import numpy as np
import pinocchio as pin
import pytest
from support import load_robot
from viewer_tabs import Harness

from c2rviz.session import Services, Session
from c2rviz.view.cell_layers import COLLISION_RGBA
from c2rviz.world.world import World

RED = tuple(int(round(255 * c)) for c in COLLISION_RGBA[:3])


@pytest.fixture
def h() -> Iterator[Harness]:
    origin = pin.SE3(pin.rpy.rpyToMatrix(0.0, 0.0, 0.4), np.array([0.3, -0.2, 0.1]))
    world = World({"arm": load_robot()}, origins={"arm": origin})
    harness = Harness(world)
    yield harness
    harness.close()


def run(h: Harness, session: Session, line: str) -> str:
    reply: Any = h.call(lambda: session.run(line))
    if asyncio.isfuture(reply):
        return str(h.loop.run_until_complete(reply))
    return str(reply)


def placement(handle: Any) -> pin.SE3:
    w, x, y, z = handle.wxyz
    return pin.SE3(pin.Quaternion(w, x, y, z).toRotationMatrix(), np.array(handle.position))


def test_an_object_stands_at_its_world_place_and_goes_when_removed(h: Harness) -> None:
    session = Session(h.services, source="test")
    run(h, session, "object table box 0.2,0.2,0.2 0,0.8,0.85,0,0,0")
    layer, view = h.scene.workcells["arm"], h.scene.views["arm"]
    h.until(lambda: "table" in layer.objects, "the send that draws the table")
    node = layer.objects["table"]
    state = h.world.state("arm")
    expected = (
        state.origin * state.robot.base_placement * pin.SE3(np.eye(3), np.array([0, 0.8, 0.85]))
    )
    got = placement(view.root) * placement(node)
    np.testing.assert_allclose(got.homogeneous, expected.homogeneous, atol=1e-6)
    assert node.name == "/robots/arm/objects/table"
    run(h, session, "object all remove")
    h.until(lambda: layer.objects == {}, "the send that removes the table")
    assert node.name not in h.scene.server.scene._handle_from_node_name


def test_a_colliding_link_and_its_object_turn_red_and_the_panel_lists_them(h: Harness) -> None:
    session = Session(h.services, source="test")
    session.set_degrees(True)
    run(h, session, "object table box 0.2,0.2,0.2 0,0.8,0.85,0,0,0")
    run(h, session, "j 90,60,0,0,0,0,0")
    h.until(lambda: "table" in h.scene.workcells["arm"].colliding, "the collision to be drawn")
    layer, panel = h.scene.workcells["arm"], h.scene.panels["arm"]
    pairs = h.world.contacts.pairs["arm"]
    links = layer.colliding - {"table"}
    assert links and links <= set(h.scene.views["arm"].link_frames)
    assert tuple(layer.objects["table"].color) == RED
    assert all(node.visible for link in links for node in layer._overlays[link])
    assert "~table" in panel.collisions.value, pairs
    run(h, session, "home")
    h.until(lambda: not layer.colliding, "the collision to end")
    assert tuple(layer.objects["table"].color) != RED
    assert not any(node.visible for nodes in layer._overlays.values() for node in nodes)
    assert panel.collisions.value == "none"


def test_the_trail_checkbox_runs_trail_on_and_the_node_holds_the_keepers_segments(
    h: Harness,
) -> None:
    tab = h.tab()
    panel = h.scene.panels["arm"]
    tab.set(panel.trail, True)
    keeper = h.services.trails
    h.until(lambda: "arm" in keeper.trails, "the checkbox to turn the trail on")
    session = Session(h.services, source="test")
    session.set_degrees(True)
    for line in ("j 30,20,0,0,0,0,0", "j 60,40,0,10,0,0,0", "j 0,0,0,0,0,0,0"):
        run(h, session, line)
        h.run(0.05)
    h.until(lambda: h.scene.trails.drawn == keeper.changed, "the trail to be drawn")
    node = h.scene.trails.nodes["arm"]
    assert len(keeper.segments("arm")) >= 2
    np.testing.assert_allclose(node.points, keeper.segments("arm"), atol=1e-6)
    state, root = h.world.state("arm"), placement(h.scene.views["arm"].root)
    tip = state.origin * state.robot.base_placement * state.robot.ee_pose(state.q)
    np.testing.assert_allclose(root.act(node.points[-1, 1]), tip.translation, atol=1e-5)
    tab.set(panel.trail, False)
    h.until(lambda: "arm" not in keeper.trails, "the checkbox to turn the trail off")
    h.until(lambda: "arm" not in h.scene.trails.nodes, "the trail node to go")
    run(h, session, "trail on")
    h.until(lambda: panel.trail.value is True, "the checkbox to follow a typed trail on")


def test_a_page_started_after_the_workcell_shows_its_objects_and_collisions() -> None:
    world = World(load_robot())
    services = Services(world, rng=np.random.default_rng(7))
    session = Session(services, source="test")
    session.set_degrees(True)
    session.run("object table box 0.2,0.2,0.2 0,0.8,0.85,0,0,0")
    world.set_q(tuple(np.radians([90.0, 60.0, 0, 0, 0, 0, 0])))
    assert world.contacts.now(world.default)
    h = Harness(world, services=services)
    try:
        layer = h.scene.workcells[world.default]
        assert set(layer.objects) == {"table"}
        assert "table" in layer.colliding
        assert "~table" in h.scene.panels[world.default].collisions.value
    finally:
        h.close()
