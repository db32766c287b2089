"""A recorded pick and place in a real headless Chromium: the part is at its start pose at
t = 0 and at its end pose at the end, on the page (viser's node) and in the player's state."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin
import pytest
from browser_support import wait_until
from support import Client

from tests.browser.test_browser_record_page import STATE, open_recording
from tests.observers.test_record_parts import RUN, SETUP, _server

pytestmark = pytest.mark.browser

NODE = """() => {
  const p = window.__viserMutable.nodePoseData['/parts/robot/p1'];
  return p ? [...p.position] : null;
}"""


def test_the_recorded_page_shows_the_part_at_its_start_and_its_end(
    tmp_path: Path, browser: Any
) -> None:
    server = _server(tmp_path)
    client = Client(server.host, server.port)
    try:
        for line in SETUP:
            assert client.ask(line).startswith("ok"), line
        assert client.ask("record take").startswith("ok recording take")
        for line in RUN:
            assert client.ask(line).startswith("ok"), line
        assert client.ask("record stop").startswith("ok")
    finally:
        client.close()
        server.stop()
    csv = np.genfromtxt(tmp_path / "take.csv", delimiter=",", names=True)
    start = np.array([csv[f"p1{a}"][0] for a in ("x", "y", "z")])
    end = np.array([csv[f"p1{a}"][-1] for a in ("x", "y", "z")])
    page = open_recording(browser, tmp_path / "take.html")
    for seconds, where in ((0.0, start), (page.evaluate(STATE)["endS"], end)):
        assert page.evaluate(f"window.__c2rvizPlayer.seek({seconds})") is True
        state = wait_until(lambda t=seconds: ((s := page.evaluate(STATE))["time"] == t, s), "seek")
        np.testing.assert_allclose(state["parts"]["p1"][:3], where, atol=1e-6)
        drawn = pin.SE3.Identity().act(where)  # the fanuc stands at the world's origin
        wait_until(
            lambda w=drawn: (
                (p := page.evaluate(NODE)) is not None and np.allclose(p, w, atol=1e-5),
                p,
            ),
            f"p1 drawn at {seconds} s",
        )
    assert state["parts"]["p2"] is None  # removed by the end
