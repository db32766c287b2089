"""The page's parts and goals, on a real ``ViserScene``: each part at its world pose with
a label (``held by ...`` while held), each goal an outline, and removed ones gone."""

from __future__ import annotations

import asyncio
from collections.abc import Iterator
from typing import Any

import numpy as np
import pinocchio as pin
import pytest
from support import load_robot
from viewer_tabs import Harness

from c2rviz.session import Session
from c2rviz.world.world import World

PICK = "0,0.3,-0.3,0,-0.9707963,0"  # the fanuc pointing down at the part (test_part_verbs)


@pytest.fixture
def h() -> Iterator[Harness]:
    origin = pin.SE3(np.eye(3), np.array([0.0, 0.5, 0.0]))
    world = World({"arm": load_robot("fanuc_lrmate200id")}, origins={"arm": origin})
    harness = Harness(world)
    yield harness
    harness.close()


def run(h: Harness, session: Session, line: str) -> str:
    reply: Any = h.call(lambda: session.run(line))
    if asyncio.isfuture(reply):
        return str(h.loop.run_until_complete(reply))
    return str(reply)


def test_parts_stand_at_their_world_pose_held_is_marked_and_goals_are_outlines(
    h: Harness,
) -> None:
    session = Session(h.services, source="test")
    layer = h.scene.parts
    assert run(h, session, "grip 1") == "ok"
    assert run(h, session, "part p1 box 0.03,0.03,0.05 0.4438,0,0.339,0,0,0") == "ok"
    h.until(lambda: "p1" in layer.nodes, "the send that draws p1")
    node, label, _ = layer.nodes["p1"]
    assert node.name == "/parts/p1"
    np.testing.assert_allclose(node.position, [0.4438, 0.5, 0.339], atol=1e-6)  # the world's
    assert label.text == "p1" and node.opacity is None
    assert run(h, session, f"joints {PICK}") == "ok"
    assert run(h, session, "grip 0").startswith("ok 0.")
    h.until(lambda: label.text == "p1 (held by arm)", "the held part's label")
    assert node.opacity is not None
    assert run(h, session, "goal p1 0.5,0.2,0.025,0,0,0") == "ok"
    h.until(lambda: "p1" in layer.goals, "the goal's outline")
    goal = layer.goals["p1"]
    assert goal.wireframe and tuple(goal.dimensions) == pytest.approx((0.03, 0.03, 0.05))
    np.testing.assert_allclose(goal.position, [0.5, 0.7, 0.025], atol=1e-6)
    assert run(h, session, "part p1 remove") == "ok"
    h.until(lambda: layer.nodes == {}, "the send that removes p1")
    assert run(h, session, "goal all remove") == "ok"
    h.until(lambda: layer.goals == {}, "the send that removes the goal")
