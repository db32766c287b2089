"""Cartesian input on the page, in a real headless Chromium with the whole program behind it.

The tool handle: the mouse drags one of its arrows, and the arm follows by IK
(the screenshot changes, and so does ``where`` on the command port). A marker
as a target: the mouse clicks a marker, the panel names it, "Go to marker"
moves the tool onto it (``pose`` on the command port equals the marker's).

Where to press is found on the page itself: the three.js objects of our nodes
(``/handles/ROBOT``, ``/markers/ROBOT/SHAPE``) projected with the page's own
camera. Waits are on signals with generous deadlines, as in test_browser.py.
"""

from __future__ import annotations

import math
from typing import Any

import pytest
from browser_support import LastingProgram, changed, field, settle, wait_for, wait_until

pytestmark = pytest.mark.browser

ROBOT = "motoman_sia20d"  # also its node segment

# The handle's arrows: drei's pivot controls hit-test translation arrows on invisible
# cylinders. Each arrow's centre and the handle's centre, in viewport pixels.
FIND_ARROWS = """(name) => {
  const m = window.__viserMutable, handle = m && m.nodeRefFromName[name];
  if (!handle || !m.camera) return null;
  handle.updateWorldMatrix(true, true);
  const V = handle.position.constructor, rect = m.canvas.getBoundingClientRect();
  const toScreen = (v) => {
    const n = v.clone().project(m.camera);
    return [rect.left + (n.x * 0.5 + 0.5) * rect.width,
            rect.top + (-n.y * 0.5 + 0.5) * rect.height];
  };
  const arrows = [];
  handle.traverse((o) => {
    if (o.isMesh && o.geometry && o.geometry.type === 'CylinderGeometry') {
      arrows.push(toScreen(o.getWorldPosition(new V())));
    }
  });
  return arrows.length ? {centre: toScreen(handle.getWorldPosition(new V())), arrows} : null;
}"""

# Marker ``index`` of a batched node, in viewport pixels (its position is node-local).
FIND_MARKER = """([name, index]) => {
  const m = window.__viserMutable, node = m && m.nodeRefFromName[name];
  const at = window.__viserSceneTree.getState()[name]?.message?.props?.batched_positions;
  if (!node || !at || !m.camera) return null;
  const xyz = new Float32Array(at.buffer.slice(at.byteOffset, at.byteOffset + at.byteLength));
  node.updateWorldMatrix(true, false);
  const p = new node.position.constructor(xyz[3 * index], xyz[3 * index + 1], xyz[3 * index + 2]);
  const n = p.applyMatrix4(node.matrixWorld).project(m.camera);
  const rect = m.canvas.getBoundingClientRect();
  return [rect.left + (n.x * 0.5 + 0.5) * rect.width, rect.top + (-n.y * 0.5 + 0.5) * rect.height];
}"""


def numbers(reply: str) -> list[float]:
    assert reply.startswith("ok "), reply
    return [float(v) for v in reply[3:].split(",")]


def test_dragging_the_tool_handle_moves_the_arm(browser: Any, motoman: LastingProgram) -> None:
    with motoman.session() as (_proc, page, tcp):
        home = tcp.ask("where")
        before = settle(page, "handle-1-before")
        found = wait_until(
            lambda: ((f := page.evaluate(FIND_ARROWS, f"/handles/{ROBOT}")) is not None, f),
            "the tool handle's arrows on the page",
        )
        cx, cy = found["centre"]
        # The arrow drawn longest on screen: a drag along it moves the handle most.
        hx, hy = max(found["arrows"], key=lambda a: math.hypot(a[0] - cx, a[1] - cy))
        length = math.hypot(hx - cx, hy - cy)
        assert length > 5, found  # the arrow is on screen, not seen end-on
        # Back along the arrow: at home the arm is stretched up, and further out is unreachable.
        ex, ey = hx - (hx - cx) / length * 50, hy - (hy - cy) / length * 50
        page.mouse.move(hx, hy)
        page.mouse.down()
        page.mouse.move(ex, ey, steps=15)
        page.mouse.up()
        moved = wait_until(
            lambda: ((now := tcp.ask("where")) != home, now), "the arm to follow the handle"
        )
        assert moved.startswith("ok ") and len(numbers(moved)) == 7
        wait_for(lambda: changed(before, settle(page, "handle-2-after")) > 200, "a new picture")
        assert "moveto " in field(page, "Last commands").input_value()


def test_clicking_a_marker_and_go_to_puts_the_tool_on_it(
    browser: Any, motoman: LastingProgram
) -> None:
    with motoman.session() as (_proc, page, tcp):
        # A marker where the tool stands at a reachable pose, then back home.
        for line in ("degrees", "move 1,3,5 30,-40,45", "marker cube", "mark"):
            assert tcp.ask(line) == "ok", line
        marked = numbers(tcp.ask("pose"))
        assert tcp.ask("home") == "ok"
        assert field(page, "Marker").input_value() == "click one in the scene"
        at = wait_until(
            lambda: (
                (p := page.evaluate(FIND_MARKER, [f"/markers/{ROBOT}/cube", 0])) is not None,
                p,
            ),
            "the marker on the page",
        )
        settle(page, "marker-1-home")
        page.mouse.click(*at)
        wait_for(lambda: field(page, "Marker").input_value().startswith("x "), "the marker chosen")
        page.get_by_role("button", name="Go to marker").click()
        wait_for(
            lambda: all(abs(a - b) < 1e-3 for a, b in zip(numbers(tcp.ask("pose")), marked[:3])),
            "the tool on the marker",
        )
        reached = numbers(tcp.ask("pose"))
        assert all(abs(a - b) < 1e-4 for a, b in zip(reached[:3], marked[:3])), (reached, marked)
        turned = [abs(a - b) % 360.0 for a, b in zip(reached[3:], marked[3:])]
        assert all(min(d, 360.0 - d) < 0.1 for d in turned), (reached, marked)
        assert "moveto marker 1" in field(page, "Last commands").input_value()
        settle(page, "marker-2-there")
