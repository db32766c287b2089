"""The tool handle: dragging it in a page moves the arm by IK, or snaps back.

A real ``ViserScene`` on a real ``World`` (``viewer_tabs.Harness``), and a page
over a real websocket that sends viser's transform-controls messages.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator
from typing import Any

import numpy as np
import pinocchio as pin
import pytest
from support import load_robot
from viewer_tabs import Harness, Tab

from c2rviz.view import adapter
from c2rviz.view.handle import moveto_line
from c2rviz.view.robot_view import wxyz
from c2rviz.world.world import RobotState, World


@pytest.fixture
def harness() -> Iterator[Callable[..., Harness]]:
    made: list[Harness] = []

    def make(world: World) -> Harness:
        made.append(Harness(world, rng=np.random.default_rng(5)))
        return made[-1]

    yield make
    for h in made:
        h.close()


def cell() -> World:
    """Two copies of one arm, the second turned and shifted, its tool 10 cm out."""
    motoman = load_robot("motoman_sia20d")
    origins = {"b": pin.SE3(pin.rpy.rpyToMatrix(0.0, 0.0, 0.4), np.array([1.0, -0.3, 0.05]))}
    world = World({"a": motoman, "b": motoman}, origins=origins)
    world.set_tool("b", pin.SE3(pin.rpy.rpyToMatrix(0.0, 0.3, 0.0), np.array([0.0, 0.0, 0.1])))
    return world


def tool_in_world(state: RobotState, q: Any = None) -> pin.SE3:
    robot = state.robot
    chain = state.q if q is None else q
    return state.origin * robot.base_placement * robot.ee_pose(chain) * state.tool


def node_pose(node: Any) -> pin.SE3:
    w, x, y, z = node.wxyz
    return pin.SE3(pin.Quaternion(w, x, y, z).toRotationMatrix(), np.array(node.position))


def drag(tab: Tab, node: Any, pose: pin.SE3, **changes: Any) -> None:
    message = {
        "type": "TransformControlsUpdateMessage",
        "name": node._impl.name,
        "wxyz": tuple(wxyz(pose.rotation).tolist()),
        "position": tuple(pose.translation.tolist()),
    }
    message.update(changes)
    tab.send(message)


def test_the_handle_stands_at_each_tool_point_and_a_drag_moves_that_arm(
    harness: Callable[..., Harness],
) -> None:
    world = cell()
    h = harness(world)
    tab = h.tab()
    handles = h.scene.handles
    for name, state in world.robots.items():
        assert node_pose(handles.nodes[name]).isApprox(tool_in_world(state), 1e-9), name
    b = world.state("b")
    goal_q = np.array(b.q) + np.radians([20.0, -15.0, 10.0, 25.0, -20.0, 30.0, 15.0])
    goal = tool_in_world(b, goal_q)
    start_a = world.state("a").q
    drag(tab, handles.nodes["b"], goal)
    h.until(lambda: b.q != world.robot.home, "robot b to move")
    reached = tool_in_world(b)
    assert np.linalg.norm(reached.translation - goal.translation) < 1e-4
    assert np.linalg.norm(pin.log3(reached.rotation.T @ goal.rotation)) < 1e-4
    assert world.state("a").q == start_a
    lines = [line for line, ok in h.scene._commands if ok]
    assert lines and lines[0].startswith("moveto ")
    h.until(
        lambda: node_pose(handles.nodes["b"]).isApprox(tool_in_world(b), 1e-9),
        "the handle to follow the arm",
    )
    assert handles.refused == 0


def test_an_unreachable_drag_leaves_the_arm_and_puts_the_handle_back(
    harness: Callable[..., Harness],
) -> None:
    world = World(load_robot("motoman_sia20d"))
    h = harness(world)
    tab = h.tab()
    state = world.state()
    node = h.scene.handles.nodes[world.default]
    home = tool_in_world(state)
    far = pin.SE3(home.rotation, home.translation + np.array([3.0, 0.0, 0.0]))
    sent_before = len(tab.received)
    drag(tab, node, far)
    h.until(lambda: h.scene.handles.refused == 1, "the drag to be refused")
    assert world.q == world.robot.home
    name = node._impl.name

    def put_back() -> bool:
        with tab._changed:
            later = tab.received[sent_before:]
        return any(
            m["type"] == "SetPositionMessage"
            and m["name"] == name
            and np.allclose(m["position"], home.translation, atol=1e-9)
            for m in later
        )

    h.until(put_back, "the tab to be told the handle's true place")
    assert node_pose(node).isApprox(home, 1e-9)
    # The one way in: the page session ran a moveto, and IK refused it.
    ran = [line for line, ok in h.scene._commands if line.startswith("moveto")]
    assert ran == [moveto_line(state, far)]


@pytest.mark.parametrize("bad", ["unknown-name", "nan", "not-unit", "extra-field"])
def test_a_bad_drag_is_dropped(harness: Callable[..., Harness], bad: str) -> None:
    world = World(load_robot("motoman_sia20d"))
    h = harness(world)
    tab = h.tab()
    state = world.state()
    node = h.scene.handles.nodes[world.default]
    near = tool_in_world(state, np.array(state.q) + 0.1)
    options: dict[str, dict[str, Any]] = {
        "unknown-name": {"name": "/robots/x"},
        "nan": {"position": (math.nan, 0.0, 0.5)},
        "not-unit": {"wxyz": (0.5, 0.0, 0.0, 0.0)},
        "extra-field": {"scale": 2.0},
    }
    changes = options[bad]
    door = adapter.door(h.scene.server)
    drag(tab, node, near, **changes)
    h.until(lambda: door.refused["handle"] == 1, "the door to drop it")
    h.run(0.05)
    assert world.q == world.robot.home
    assert not [line for line, ok in h.scene._commands if line.startswith("moveto")]
    # The same drag, well formed, moves the arm.
    drag(tab, node, near)
    h.until(lambda: world.q != world.robot.home, "a good drag after")
    assert np.linalg.norm(tool_in_world(state).translation - near.translation) < 1e-4


def test_a_held_handle_stays_in_the_hand_and_follows_the_arm_when_let_go(
    harness: Callable[..., Harness],
) -> None:
    world = World(load_robot("motoman_sia20d"))
    h = harness(world)
    tab = h.tab()
    state = world.state()
    node = h.scene.handles.nodes[world.default]
    home = tool_in_world(state)
    name = node._impl.name
    tab.send({"type": "TransformControlsDragStartMessage", "name": name})
    h.until(lambda: h.scene.handles.busy(world.default), "the tab to hold the handle")
    moved = np.array(state.q) + 0.2
    h.call(lambda: world.set_q(moved.tolist()))  # a TCP client moves the arm meanwhile
    h.until(lambda: h.scene.views[world.default].sent_q == world.q, "the arm to be drawn")
    assert node_pose(node).isApprox(home, 1e-9)  # not pulled out of the hand
    tab.send({"type": "TransformControlsDragEndMessage", "name": name})
    h.until(lambda: node_pose(node).isApprox(tool_in_world(state), 1e-9), "the handle to follow")
    assert adapter.door(h.scene.server).refused["handle"] == 0
