"""The trail in a real headless Chromium: after a move in motion, the page shows a line
along the tool's path; `trail off` takes it away. Waits are on signals (test_browser.py)."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from browser_support import LastingProgram, scene_pixels, settle, wait_for

pytestmark = pytest.mark.browser

# Where the trail's node is in the page's scene tree, and how many segments it holds.
TRAIL_SEGMENTS = """(name) => {
  const node = window.__viserSceneTree.getState()[name];
  const points = node?.message?.props?.points;
  return points ? points.byteLength / 24 : null;
}"""


def orange_pixels(scene: np.ndarray) -> int:
    """Pixels of the trail's orange (1.0, 0.6, 0.0)."""
    r, g, b = scene[..., 0], scene[..., 1], scene[..., 2]
    return int(((r > 200) & (g > 100) & (g < 200) & (b < 80)).sum())


def test_a_move_leaves_a_trail_on_the_page(browser: Any, motoman: LastingProgram) -> None:
    with motoman.session() as (_proc, page, tcp):
        before = orange_pixels(settle(page, "trail-1-before"))
        for line in ("trail on", "motion on", "speed 100", "degrees"):
            assert tcp.ask(line) == "ok"
        assert tcp.ask("j 70,40,0,-50,0,40,0") == "ok"  # the reply comes on arrival
        segments = tcp.ask("trail")
        assert segments.startswith("ok on ") and int(segments.split()[-1]) > 30
        node = "/robots/motoman_sia20d/trail"
        wait_for(
            lambda: (page.evaluate(TRAIL_SEGMENTS, node) or 0) >= int(segments.split()[-1]) - 1,
            "the trail's segments on the page",
        )
        wait_for(lambda: orange_pixels(scene_pixels(page)) > before + 100, "the trail drawn")
        drawn = orange_pixels(settle(page, "trail-2-drawn"))
        assert drawn > before + 100
        assert tcp.ask("trail off") == "ok"
        wait_for(lambda: page.evaluate(TRAIL_SEGMENTS, node) is None, "the trail removed")
        wait_for(lambda: orange_pixels(scene_pixels(page)) <= before + 5, "the trail gone")
        settle(page, "trail-3-off")
