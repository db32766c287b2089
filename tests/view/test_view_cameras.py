"""The page's cameras, on a real ``ViserScene``: each frustum at its camera's world pose,
its edges the field of view and range, and a removed camera gone."""

from __future__ import annotations

import asyncio
import math
from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest
from support import load_robot
from viewer_tabs import Harness

from c2rviz.session import Session
from c2rviz.world.world import World


@pytest.fixture
def h() -> Iterator[Harness]:
    harness = Harness(World({"arm": load_robot("fanuc_lrmate200id")}))
    yield harness
    harness.close()


def run(h: Harness, session: Session, line: str) -> str:
    reply: Any = h.call(lambda: session.run(line))
    if asyncio.isfuture(reply):
        return str(h.loop.run_until_complete(reply))
    return str(reply)


def test_a_camera_is_drawn_as_its_frustum_and_goes_when_removed(h: Harness) -> None:
    session = Session(h.services, source="test")
    layer = h.scene.cameras
    assert run(h, session, "camera top 0.5,0,1,0,1.5707963267948966,0 1.2,0.8,1.5") == "ok"
    h.until(lambda: "top" in layer.nodes, "the send that draws the camera")
    node, label, _ = layer.nodes["top"]
    assert node.name == "/cameras/top" and label.text == "top: none"
    np.testing.assert_allclose(node.position, [0.5, 0, 1], atol=1e-6)
    # Looking down: pitch 90 deg about y.
    half = math.sqrt(0.5)
    np.testing.assert_allclose(np.abs(node.wxyz), [half, 0, half, 0], atol=1e-6)
    points = np.asarray(node.points)
    assert points.shape == (8, 2, 3)
    far = points[:4, 1]
    np.testing.assert_allclose(far[:, 0], 1.5, atol=1e-6)
    np.testing.assert_allclose(np.abs(far[:, 1]), 1.5 * math.tan(0.6), atol=1e-5)
    np.testing.assert_allclose(np.abs(far[:, 2]), 1.5 * math.tan(0.4), atol=1e-5)
    assert run(h, session, "part p1 box 0.03,0.03,0.03 0.5,0,0.015,0,0,0") == "ok"
    h.until(lambda: label.text == "top: p1", "the label naming what the camera sees")
    assert layer.nodes["top"][0] is node  # only the label changed
    assert run(h, session, "object lid box 0.3,0.3,0.01 0.5,0,0.5,0,0,0") == "ok"
    h.until(lambda: label.text == "top: none", "the lid hiding p1")
    h.call(lambda: h.world.cameras.blackout("top", math.inf))
    h.until(lambda: layer.nodes["top"][1].text == "top: dark", "the blackout")
    assert run(h, session, "camera top remove") == "ok"
    h.until(lambda: layer.nodes == {}, "the send that removes the camera")
