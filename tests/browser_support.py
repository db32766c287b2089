"""The page in a real headless Chromium, with the whole program behind it.

One test walks through what a user sees: the robot drawn, TCP commands moving
it, a slider on the page commanding the world (read back with ``where``), a
late second tab showing the same state, markers appearing and ``clear``
taking the page back to how it started. Screenshots go to test-artifacts/.

Every wait is on a signal with a generous deadline, never on a short timer: the
page's own state (viser's end-to-end hooks: the scene tree, node poses, the
message queue and three.js's frame counter) says when a change has arrived and
been drawn, and only then are pixels compared. Software WebGL on a busy 2-core
CI machine is slow, not wrong; a timeout says what it last saw.
"""

from __future__ import annotations

import asyncio
import contextlib
import io
import socket
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np
from support import ROOT, start_program

ARTIFACTS = ROOT / "test-artifacts"
VIEWPORT = {"width": 1000, "height": 700}
# Where the robot is drawn: right of viser's 'software WebGL' notice, left of the panel.
SCENE = (slice(160, 700), slice(320, 660))
JOINTS = ("joint_s", "joint_l", "joint_e", "joint_u", "joint_r", "joint_b", "joint_t")
DEADLINE_S = 180.0  # for any one wait; a healthy run takes a second or two per step
PLAIN = ("--viewer-lighting", "plain")
"""The program's flags for a page lit without viser's environment map and shadows: in
software WebGL its first drawing of the robot takes a third of the CPU (docs/testing.md).
Every browser test's program takes them, but one that keeps the default lighting
(test_browser.py, the object and the red collision)."""

# viser's end-to-end hooks (App.tsx puts them on window for Playwright): the one place
# this file reads the page's internals. Robot links nest as the URDF's tree,
# /robots/ROBOT/links/ROOT/.../LINK, each posed in its parent's frame (``in_root`` composes
# them); their geometry /robots/ROBOT/links/.../LINK/visual_K, markers batched in
# /markers/ROBOT/SHAPE (c2rviz/view/).
# A link's frame node under /robots/ROBOT/links/ (not its geometry nor the tool's axes).
LINK_NODE_JS = """(n) => /^\\/robots\\/[^/]+\\/links\\//.test(n)
  && !/\\/((visual|collision|overlay)_\\d+|ee)$/.test(n)"""
PAGE_STATE = """() => {
  const m = window.__viserMutable, t = window.__viserSceneTree, tp = window.__viserTestpoints;
  if (!m || !t || !tp) return null;
  const nodes = Object.keys(t.getState());
  const visuals = nodes.filter((n) => /^\\/robots\\/[^/]+\\/links\\/.+\\/visual_\\d+$/.test(n));
  const poses = {};
  for (const [n, p] of Object.entries(m.nodePoseData)) {
    if (LINK_NODE(n)) poses[n] = [...p.wxyz, ...p.position];
  }
  let markers = 0;  // one batched node per robot and shape: count its instances
  for (const n of nodes.filter((n) => /^\\/markers\\//.test(n))) {
    const at = t.getState()[n]?.message?.props?.batched_positions;
    markers += at ? at.byteLength / 12 : 0;
  }
  return {
    visuals: visuals.length,
    mounted: visuals.filter((n) => m.nodeRefFromName[n]).length,
    markers,
    queued: m.messageQueue.length,
    frame: tp.rendererInfo.render.frame,
    poses,
  };
}""".replace("LINK_NODE", f"({LINK_NODE_JS})")


class FreshContexts:
    """The session's one Chromium as each test sees it: ``new_page`` opens a page in a new
    browser context (cookies, storage and viewport of its own, as a fresh browser has),
    ``new_context`` a context; ``close_contexts`` closes what a test opened.

    A Chromium that died is launched again before the next test.

    Playwright's sync API marks its event loop as this thread's running loop between its
    calls; a session-long Playwright would then refuse every later test's ``asyncio.run``.
    ``close_contexts`` (after each browser test) unmarks it, ``resume`` (before) marks it again.
    """

    def __init__(self, launch: Callable[[], Any]) -> None:
        self._launch = launch
        self._browser = launch()
        self._contexts: list[Any] = []
        self._loop: asyncio.AbstractEventLoop | None = asyncio._get_running_loop()

    def _context(self, **options: Any) -> Any:
        """A new context whose actions (a click waits for its button to be visible and
        still, a ``fill`` for its box) wait as long as the tests' own waits: Playwright's
        30 s default ran out once on a 2-core machine at load 13, a recorded page's button
        not yet still."""
        context = self._browser.new_context(**options)
        context.set_default_timeout(DEADLINE_S * 1000)
        return context

    def new_context(self, **options: Any) -> Any:
        context = self._context(**options)
        self._contexts.append(context)
        return context

    def new_page(self, **options: Any) -> Any:
        return self.new_context(**options).new_page()

    def lasting_page(self, **options: Any) -> Any:
        """A page in a context of its own that outlives the test (``close_contexts`` leaves
        it): for a ``LastingProgram``, closed by its owner."""
        return self._context(**options).new_page()

    def unmark(self) -> None:
        asyncio._set_running_loop(None)

    @contextlib.contextmanager
    def marked(self) -> Iterator[None]:
        """Playwright's loop marked as in ``resume`` for a fixture's own use of Chromium
        outside a test's (a shared program's page), then as it was."""
        was = asyncio._get_running_loop()
        self.resume()
        try:
            yield
        finally:
            if was is None:
                self.unmark()

    def resume(self) -> None:
        """Before a test: the loop marked again, and a new Chromium if the last one died
        (one test's crash must not fail every later browser test)."""
        if self._loop is not None:
            asyncio._set_running_loop(self._loop)
        if not self._browser.is_connected():
            self._browser = self._launch()

    def close_contexts(self) -> None:
        try:
            while self._contexts:
                self._contexts.pop().close()
        finally:
            self.unmark()

    def __getattr__(self, name: str) -> Any:
        return getattr(self._browser, name)


def in_root(poses: dict[str, list[float]]) -> dict[str, np.ndarray]:
    """Link node poses (w, x, y, z, px, py, pz, each in its parent link's frame, as the
    page holds them) in their robot's root frame, by ``/robots/ROBOT/links/LINK``."""
    import pinocchio as pin

    def se3(p: list[float]) -> pin.SE3:
        w, x, y, z, *position = p
        return pin.SE3(
            pin.Quaternion(w, x, y, z).normalized().toRotationMatrix(), np.array(position)
        )

    out = {}
    for name in poses:
        robot, path = name.split("/links/", 1)
        segments = path.split("/")
        pose = pin.SE3.Identity()
        for k in range(len(segments)):
            above = f"{robot}/links/" + "/".join(segments[: k + 1])
            pose = pose * se3(poses.get(above, [1.0, 0, 0, 0, 0, 0, 0]))
        x, y, z, w = pin.Quaternion(pose.rotation).coeffs()
        out[f"{robot}/links/{segments[-1]}"] = np.array([w, x, y, z, *pose.translation])
    return out


class Tcp:
    """A controller on the command port."""

    def __init__(self, port: int) -> None:
        self.sock = socket.create_connection(("127.0.0.1", port), timeout=10)
        self.file = self.sock.makefile("rb")

    def ask(self, line: str) -> str:
        self.sock.sendall(line.encode() + b"\n")
        return self.file.readline().decode().strip()

    def close(self) -> None:
        self.file.close()
        self.sock.close()


def crop(png: bytes) -> np.ndarray:
    """The scene's region of a screenshot (PNG bytes of the page)."""
    from PIL import Image

    image = Image.open(io.BytesIO(png)).convert("RGB")
    return np.asarray(image, dtype=np.int16)[SCENE]


def scene_pixels(page: Any) -> np.ndarray:
    return crop(page.screenshot())


def settle(page: Any, name: str, timeout_s: float = 60.0) -> np.ndarray:
    """The drawn scene once two screenshots in a row agree; the first of them saved as
    ``name``.png (a screenshot waits for a new frame: 0.4-0.6 s each on a busy machine,
    so the one compared is the one kept, not a third)."""
    png = page.screenshot()
    previous = crop(png)
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        page.wait_for_timeout(150)
        now = page.screenshot()
        current = crop(now)
        if np.array_equal(current, previous):
            break
        png, previous = now, current
    ARTIFACTS.mkdir(exist_ok=True)
    (ARTIFACTS / f"{name}.png").write_bytes(png)
    return previous


def blue_pixels(scene: np.ndarray) -> int:
    """Pixels of the motoman's light blue (0.45, 0.68, 0.90), lit or shaded."""
    r, b = scene[..., 0], scene[..., 2]
    return int(((b - r > 60) & (b > 150)).sum())


def wait_until(check: Callable[[], tuple[bool, Any]], what: str) -> Any:
    """Poll ``check`` (it returns done, what it saw) until done; return what it saw.

    Fails after ``DEADLINE_S`` naming ``what``, with what was seen along the way
    (every 10 s and last), so a slow machine and a real fault can be told apart.
    """
    start = time.monotonic()
    seen: list[str] = []
    while True:
        done, state = check()
        if done:
            return state
        waited = time.monotonic() - start
        if not seen or waited >= 10 * len(seen):
            seen.append(f"{waited:.0f} s: {state}")
        assert waited < DEADLINE_S, f"{what} (after {waited:.0f} s; saw {seen}, last {state})"
        time.sleep(0.1)


def page_state(page: Any) -> dict[str, Any] | None:
    """What the page holds: robot visuals (and how many are mounted), markers, poses."""
    return page.evaluate(PAGE_STATE)


def same_poses(a: dict[str, list[float]], b: dict[str, list[float]], tol: float = 1e-6) -> bool:
    return a.keys() == b.keys() and all(np.allclose(a[k], b[k], atol=tol) for k in a)


def wait_for_scene(
    page: Any, what: str, expect: Callable[[dict[str, Any]], bool] = lambda state: True
) -> dict[str, Any]:
    """Wait until the page holds ``expect``'s scene, steadily, and has drawn a frame of it.

    Steady: every scene message applied (empty queue), every robot visual
    mounted, and the same nodes and poses in two polls in a row.
    """
    previous: list[dict[str, Any] | None] = [None]

    def ready() -> tuple[bool, Any]:
        state = page_state(page)
        if state is None:
            return False, "viser's test hooks not on the page (yet)"
        steady = {k: v for k, v in state.items() if k != "frame"}
        done = (
            state["visuals"] > 0
            and state["mounted"] == state["visuals"]
            and state["queued"] == 0
            and expect(state)
            and steady == previous[0]
        )
        previous[0] = steady
        return done, state

    state = wait_until(ready, f"the page did not show {what}")
    frame = state["frame"]
    wait_until(
        lambda: ((now := page_state(page)) is not None and now["frame"] > frame, now),
        f"the page did not draw {what}",
    )
    return state


def wait_for_robot(page: Any) -> dict[str, Any]:
    """Wait until the robot's links are drawn, not only the panel and grid; its scene."""
    state = wait_for_scene(page, "the robot")
    wait_until(
        lambda: ((n := blue_pixels(scene_pixels(page))) >= 1000, n),
        "the robot was not drawn (blue pixels)",
    )
    return state


def changed(a: np.ndarray, b: np.ndarray) -> int:
    """How many pixels differ noticeably between two scene crops."""
    return int((np.abs(a - b).max(axis=2) > 24).sum())


def field(page: Any, label: str, css: str = "input:not([type=hidden]), textarea") -> Any:
    """The input in the panel row labelled ``label``."""
    row = page.locator("label", has_text=label).first.locator(
        "xpath=ancestor::div[contains(@class, 'mantine-Flex-root')][1]"
    )
    return row.locator(css).first


def slider_input(page: Any, joint: str) -> Any:
    """The number box beside a joint's slider."""
    return field(page, joint, "input[inputmode=decimal]")


def panel_state(page: Any) -> dict[str, str]:
    """Every slider's value and the end-effector readout, as the page shows them."""
    state = {joint: slider_input(page, joint).input_value() for joint in JOINTS}
    state["ee"] = field(page, "End effector").input_value()
    return state


def open_page(browser: Any, url: str, lasting: bool = False) -> Any:
    page = (browser.lasting_page if lasting else browser.new_page)(viewport=VIEWPORT)
    # fixedDpr: viser otherwise lowers the resolution when software WebGL is slow,
    # at a moment of its choosing, and identical scenes stop giving identical pixels.
    page.goto(url + "/?fixedDpr=1")
    page.get_by_text(JOINTS[-1]).first.wait_for(timeout=DEADLINE_S * 1000)  # the panel
    return page


class LastingProgram:
    """One program (the Motoman, its viewer on a free port, lit plainly, ``ARGS``) and a page
    with its robot drawn, shared by the tests that take it (``tests/browser/conftest.py``).

    A new page costs 3-9 s of Chromium's CPU before its robot is drawn, the program 2 s
    more (docs/testing.md): tests that only need the Motoman at home share both, and
    ``session`` puts the world back as a new program has it before each.
    """

    def __init__(self, chromium: FreshContexts, record_dir: Path, *args: str) -> None:
        ARTIFACTS.mkdir(exist_ok=True)
        self.record_dir = record_dir
        self.proc = start_program(
            "--viser-port", "0", *PLAIN, "--record-dir", str(record_dir), *args
        )
        try:
            self.page = open_page(chromium, self.proc.viewer_url, lasting=True)
            self.home_poses = wait_for_robot(self.page)["poses"]
        except BaseException:
            self.proc.stop()
            raise

    @contextlib.contextmanager
    def session(self) -> Iterator[tuple[Any, Any, Tcp]]:
        """The program, its page and a new controller on its command port (closed after),
        the world as a new program has it: at rest at home, no markers, trail off, the
        ghost on, the page live and showing all that."""
        tcp = Tcp(self.proc.port)
        try:
            for line in ("stop", "trail off", "ghost on", "clear"):
                assert tcp.ask(line) == "ok", line
            if field(self.page, "Shown").input_value() != "live":
                self.page.get_by_role("button", name="live", exact=True).click()
            wait_for_scene(
                self.page,
                "the arm at home, no markers",
                lambda state: state["markers"] == 0 and same_poses(state["poses"], self.home_poses),
            )
            wait_for(lambda: field(self.page, "Shown").input_value() == "live", "the page live")
            yield self.proc, self.page, tcp
        finally:
            tcp.close()

    def close(self) -> None:
        try:
            self.page.context.close()
        finally:
            self.proc.stop()


def wait_for(predicate: Callable[[], bool], what: str = "timed out") -> None:
    wait_until(lambda: (predicate(), None), what)
