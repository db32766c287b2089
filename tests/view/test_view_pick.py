"""Markers as targets: a click on a marker in a page chooses it, "Go to marker" goes there.

A real ``ViserScene`` on a real ``World`` (``viewer_tabs.Harness``), and a page
over a real websocket that sends what viser's page sends for a click on a
batched node and for a button press.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from typing import Any

import numpy as np
import pinocchio as pin
import pytest
from support import load_robot
from viewer_tabs import Harness, Tab

from c2rviz.view import adapter
from c2rviz.view.panel import NO_MARKER
from c2rviz.world.observer import MAX_MARKERS, Marker
from c2rviz.world.world import World

RED = (1.0, 0.0, 0.0)


@pytest.fixture
def h() -> Iterator[Harness]:
    harness = Harness(World(load_robot("motoman_sia20d")), rng=np.random.default_rng(3))
    yield harness
    harness.close()


def click(tab: Tab, node: Any, instance: int | None, **changes: Any) -> None:
    message = {
        "type": "SceneNodeClickMessage",
        "name": node._impl.name,
        "instance_index": instance,
        "ray_origin": (3.0, 0.0, 1.0),
        "ray_direction": (-1.0, 0.0, 0.0),
        "screen_pos": (0.5, 0.5),
        "modifier": None,
    }
    message.update(changes)
    tab.send(message)


def reachable(world: World, offset_deg: float) -> pin.SE3:
    """A tool pose (base frame) the arm reaches with every joint ``offset_deg`` from home."""
    q = np.array(world.robot.home) + math.radians(offset_deg)
    return world.robot.ee_pose(q) * world.state().tool


def drop(h: Harness, pose: pin.SE3, shape: str = "sphere") -> Marker:
    marker = h.call(lambda: h.world.add_marker(pose, RED, shape))
    h.until(lambda: not h.scene.markers.dirty, "the markers drawn")
    return marker


def tool_in_world(world: World) -> pin.SE3:
    state = world.state()
    return state.origin * state.robot.base_placement * state.robot.ee_pose(state.q) * state.tool


def test_a_clicked_marker_is_chosen_and_go_to_moves_the_tool_there(h: Harness) -> None:
    tab = h.tab()
    name = h.world.default
    panel = h.panel
    assert panel.chosen is None and panel.goto.disabled and panel.marker.value == NO_MARKER
    drop(h, reachable(h.world, 40.0))  # sphere 0
    target = drop(h, reachable(h.world, 20.0), "cube")  # cube 0
    drop(h, reachable(h.world, -20.0))  # sphere 1
    click(tab, h.scene.markers.nodes[name, "cube"], 0)
    h.until(lambda: panel.chosen is target, "the cube to be chosen")
    assert not panel.goto.disabled
    x, y, z = target.position
    assert panel.marker.value == f"x {x:+.3f}  y {y:+.3f}  z {z:+.3f} m"
    tab.set(panel.goto, True)
    h.until(lambda: h.world.q != h.world.robot.home, "the arm to move")
    w, qx, qy, qz = target.wxyz
    goal = pin.SE3(pin.Quaternion(w, qx, qy, qz).toRotationMatrix(), np.array(target.position))
    reached = tool_in_world(h.world)
    assert np.linalg.norm(reached.translation - goal.translation) < 1e-4
    assert np.linalg.norm(pin.log3(reached.rotation.T @ goal.rotation)) < math.radians(0.1)
    # The one way in: the page's session ran `moveto marker 2` (the cube is the 2nd marker).
    assert ("moveto marker 2", True) in list(h.scene._commands)


def test_clear_forgets_the_chosen_marker(h: Harness) -> None:
    tab = h.tab()
    panel = h.panel
    marker = drop(h, reachable(h.world, 30.0))
    click(tab, h.scene.markers.nodes[h.world.default, "sphere"], 0)
    h.until(lambda: panel.chosen is marker, "the marker to be chosen")
    h.call(lambda: h.world.clear(None))
    h.until(lambda: panel.chosen is None, "the choice to be forgotten")
    assert panel.goto.disabled and panel.marker.value == NO_MARKER


def test_go_to_a_marker_pushed_out_by_newer_ones_moves_nothing(h: Harness) -> None:
    tab = h.tab()
    panel = h.panel
    first = drop(h, reachable(h.world, 30.0))
    click(tab, h.scene.markers.nodes[h.world.default, "sphere"], 0)
    h.until(lambda: panel.chosen is first, "the first marker to be chosen")
    pose = reachable(h.world, -30.0)
    h.call(lambda: [h.world.add_marker(pose, RED, "cube") for _ in range(MAX_MARKERS)])
    assert first not in h.world.state().markers
    refused = h.scene.page_input.refused
    tab.set(panel.goto, True)
    h.until(lambda: h.scene.page_input.refused == refused + 1, "the press to be refused")
    assert h.world.q == h.world.robot.home
    assert panel.chosen is None and panel.goto.disabled
    assert not [line for line, _ in h.scene._commands if line.startswith("moveto")]


@pytest.mark.parametrize(
    "bad", ["unknown-node", "nan-ray", "negative-index", "extra-field", "text-index"]
)
def test_a_bad_click_is_dropped_at_the_door(h: Harness, bad: str) -> None:
    tab = h.tab()
    drop(h, reachable(h.world, 30.0))
    node = h.scene.markers.nodes[h.world.default, "sphere"]
    options: dict[str, tuple[int | None, dict[str, Any]]] = {
        "unknown-node": (0, {"name": "/robots/motoman_sia20d/links/base_link"}),
        "nan-ray": (0, {"ray_direction": (math.nan, 0.0, 0.0)}),
        "negative-index": (-1, {}),
        "extra-field": (0, {"update_cb": []}),
        "text-index": (0, {"instance_index": "0"}),
    }
    instance, changes = options[bad]
    door = adapter.door(h.scene.server)
    click(tab, node, instance, **changes)
    h.until(lambda: door.refused["click"] == 1, "the door to drop it")
    # A good click after it still works: the bad one harmed nothing.
    click(tab, node, 0)
    h.until(lambda: h.panel.chosen is not None, "the good click to choose the marker")


def test_a_click_beyond_the_drawn_markers_chooses_nothing(h: Harness) -> None:
    tab = h.tab()
    marker = drop(h, reachable(h.world, 30.0))
    node = h.scene.markers.nodes[h.world.default, "sphere"]
    click(tab, node, 0)
    h.until(lambda: h.panel.chosen is marker, "the marker to be chosen")
    picks = h.scene.page_input.picks
    click(tab, node, 5)  # a well-formed click; no sphere 5 is drawn
    h.until(lambda: h.scene.page_input.picks == picks + 1, "the click to be run")
    assert h.panel.chosen is marker  # unchanged
    assert adapter.door(h.scene.server).refused["click"] == 0
