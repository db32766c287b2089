"""The page in real headless Chromium: it follows commands, commands the robot, and keeps
its door shut to other origins (helpers in ``browser_support.py``)."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import Any

import numpy as np
import pytest
from browser_support import (
    ARTIFACTS,
    DEADLINE_S,
    PLAIN,
    VIEWPORT,
    Tcp,
    changed,
    field,
    open_page,
    panel_state,
    same_poses,
    scene_pixels,
    settle,
    slider_input,
    wait_for,
    wait_for_robot,
    wait_for_scene,
)

pytestmark = pytest.mark.browser


def test_the_page_follows_commands_and_commands_the_robot(
    browser: Any, c2rviz_process: Callable[..., Any]
) -> None:
    ARTIFACTS.mkdir(exist_ok=True)
    proc = c2rviz_process("--viser-port", "0", *PLAIN)
    assert proc.viewer_url is not None and proc.viewer_url.startswith("http://127.0.0.1:")
    page = open_page(browser, proc.viewer_url)
    # viser draws its share-link button as this icon (present by default); it is off.
    assert page.locator("svg.tabler-icon-share").count() == 0
    home_poses = wait_for_robot(page)["poses"]
    home = settle(page, "1-home")

    tcp = Tcp(proc.port)
    try:
        assert tcp.ask("degrees") == "ok"
        assert tcp.ask("move 0,1 90,45") == "ok"
        wait_for(lambda: slider_input(page, "joint_s").input_value() == "90", "slider at 90")
        moved_poses = wait_for_scene(
            page, "the move", lambda state: not same_poses(state["poses"], home_poses)
        )["poses"]
        moved = settle(page, "2-moved")
        assert changed(home, moved) > 2000
        assert "move 0,1 90,45" in field(page, "Last commands").input_value()
        assert field(page, "TCP clients").input_value() == "1"

        # The page commands the world: TCP sees the slider's value with `where`.
        box = slider_input(page, "joint_e")
        box.fill("30")
        box.press("Enter")
        wait_for(lambda: tcp.ask("where").split(",")[2] == "30", "joint_e at 30")
        assert tcp.ask("where") == "ok 90,45,30,0,0,0,0"
        poses = wait_for_scene(
            page, "the slider's move", lambda state: not same_poses(state["poses"], moved_poses)
        )["poses"]
        settle(page, "3-slider")

        # A tab opened late shows the same state at once.
        late = open_page(browser, proc.viewer_url)
        wait_for_robot(late)
        wait_for(lambda: panel_state(late) == panel_state(page), "the same panel in both tabs")
        wait_for_scene(late, "the same pose", lambda state: same_poses(state["poses"], poses))
        assert panel_state(late)["joint_e"] == "30"
        assert changed(settle(late, "4-late-tab"), settle(page, "4-first-tab")) < 20
        late.close()

        # Markers appear; `clear` removes them and homes: the page looks as it began.
        before = settle(page, "5-before-marks")
        markers = wait_for_scene(page, "the scene before the marks")["markers"]
        for line in ("rgb 255,0,0", "marker cube", "mark 0.5,-0.5,0.3,0,0,0", "mark"):
            assert tcp.ask(line) == "ok"
        wait_for_scene(page, "two markers", lambda state: state["markers"] == markers + 2)
        # Batched markers reach the GPU a frame or two after their node's state.
        wait_for(lambda: changed(before, scene_pixels(page)) > 20, "the markers drawn")
        marked = settle(page, "6-marks")
        assert changed(before, marked) > 20
        assert tcp.ask("clear") == "ok"
        wait_for(lambda: slider_input(page, "joint_s").input_value() == "0", "slider at 0")
        wait_for_scene(
            page,
            "the cleared scene",
            lambda state: state["markers"] == 0 and same_poses(state["poses"], home_poses),
        )
        cleared = settle(page, "7-cleared")
        assert changed(home, cleared) < 20
    finally:
        tcp.close()


TRY_WEBSOCKET = """([url, protocol]) => new Promise((resolve) => {
    const ws = new WebSocket(url, protocol);
    ws.onopen = () => { ws.close(); resolve("open"); };
    ws.onerror = () => resolve("refused");
})"""


@pytest.fixture
def other_origin() -> Iterator[str]:
    """A tiny page served from another local port: another origin, as any site is."""
    import http.server
    import threading

    class Page(http.server.BaseHTTPRequestHandler):
        def do_GET(self) -> None:  # noqa: N802 (http.server's name)
            body = b"<!doctype html><title>elsewhere</title><p>another site</p>"
            self.send_response(200)
            self.send_header("Content-Type", "text/html")
            self.send_header("Content-Length", str(len(body)))
            self.end_headers()
            self.wfile.write(body)

        def log_message(self, *args: Any) -> None:
            pass

    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), Page)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"http://127.0.0.1:{server.server_address[1]}"
    finally:
        server.shutdown()
        server.server_close()
        thread.join(timeout=10)


def test_a_page_from_another_origin_cannot_reach_the_viewer(
    browser: Any, c2rviz_process: Callable[..., Any], other_origin: str
) -> None:
    """Any site the user visits could open the viewer's websocket; the door refuses it.
    The viewer's own page, titled by the robot, still connects and works."""
    import viser

    proc = c2rviz_process("--viser-port", "0", *PLAIN)
    socket_url = proc.viewer_url.replace("http://", "ws://") + "/"
    protocol = f"viser-v{viser.__version__}"
    elsewhere = browser.new_page()
    elsewhere.goto(other_origin)
    assert elsewhere.evaluate(TRY_WEBSOCKET, [socket_url, protocol]) == "refused"
    elsewhere.close()
    page = open_page(browser, proc.viewer_url)
    assert page.title() == "c2rviz — motoman_sia20d"
    assert page.evaluate(TRY_WEBSOCKET, [socket_url, protocol]) == "open"  # same script, own page
    wait_for_robot(page)
    box = slider_input(page, "joint_e")
    box.fill("30")
    box.press("Enter")
    tcp = Tcp(proc.port)
    try:
        assert tcp.ask("degrees") == "ok"
        wait_for(lambda: tcp.ask("where").split(",")[2] == "30")
    finally:
        tcp.close()


def test_long_joint_names_stay_on_one_line(
    browser: Any, c2rviz_process: Callable[..., Any]
) -> None:
    """ur5's joints are named like shoulder_pan_joint: each label fits on one line."""
    ARTIFACTS.mkdir(exist_ok=True)
    proc = c2rviz_process("--robot", "ur5", "--viser-port", "0", *PLAIN)
    page = browser.new_page(viewport=VIEWPORT)
    page.goto(proc.viewer_url + "/?fixedDpr=1")
    page.get_by_text("Speed %").first.wait_for(timeout=DEADLINE_S * 1000)
    assert page.title() == "c2rviz — ur5"
    heights = {}
    for label in ("Speed %", "shoulder_pan", "shoulder_lift", "elbow", "wrist_1"):
        heights[label] = page.locator("label", has_text=label).first.bounding_box()["height"]
    page.screenshot(path=str(ARTIFACTS / "ur5-panel.png"))
    assert len(set(heights.values())) == 1, heights  # as high as a one-line label


def red_pixels(scene: np.ndarray) -> int:
    """Pixels of the collision red (a colliding link's overlay, a hit object)."""
    r, g, b = scene[..., 0], scene[..., 1], scene[..., 2]
    return int(((r > 180) & (g < 90) & (b < 90)).sum())


def test_an_object_is_drawn_and_a_link_in_it_turns_red(
    browser: Any, c2rviz_process: Callable[..., Any]
) -> None:
    ARTIFACTS.mkdir(exist_ok=True)
    proc = c2rviz_process("--viser-port", "0")  # studio: the default lighting
    page = open_page(browser, proc.viewer_url)
    wait_for_robot(page)
    home = settle(page, "objects-1-home")
    tcp = Tcp(proc.port)
    try:
        assert tcp.ask("object table box 0.2,0.2,0.2 0,0.8,0.85,0,0,0") == "ok"
        has_object = (
            "() => Object.keys(window.__viserSceneTree.getState())"
            ".some((n) => n.endsWith('/objects/table'))"
        )
        wait_for(lambda: page.evaluate(has_object), "the object's node on the page")
        wait_for(lambda: changed(home, scene_pixels(page)) > 50, "the object drawn")
        with_object = settle(page, "objects-2-table")
        assert red_pixels(with_object) < 50
        assert tcp.ask("degrees") == "ok"
        assert tcp.ask("j 90,60,0,0,0,0,0") == "ok"
        wait_for(
            lambda: "~table" in field(page, "Collisions").input_value(), "the collision listed"
        )
        wait_for(lambda: red_pixels(scene_pixels(page)) > 300, "the link and the object red")
        red = red_pixels(settle(page, "objects-3-red"))
        assert tcp.ask("home") == "ok"
        wait_for(lambda: field(page, "Collisions").input_value() == "none", "no collision listed")
        wait_for(lambda: red_pixels(scene_pixels(page)) < red // 10, "the red gone")
        settle(page, "objects-4-home")
    finally:
        tcp.close()
