"""NAME.html played in a real headless Chromium from a file:// URL, no server.

A real recording (the server, TCP clients, ``record``) is opened; the page is sought to
times forward and back, and at each the arm's link poses on the page are compared with
Pinocchio's forward kinematics of NAME.csv's frame at that time, the markers with NAME.txt,
the plots' cursor with the time. Damaged recordings open with their message. Waits are on
the player's own state (``window.__c2rvizPlayer``).
"""

from __future__ import annotations

import csv
import shutil
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin
import pytest
from browser_support import ARTIFACTS, LINK_NODE_JS, in_root, wait_until
from support import Client, ServerThread, load_robot

from c2rviz.session import ServerLimits
from c2rviz.view.record_frames import HTML_HZ, MAX_HTML_FRAMES
from c2rviz.world.state import RobotState
from c2rviz.world.virtual_clock import VirtualClock

pytestmark = pytest.mark.browser

LINKS = "/robots/robot/links/"
STATE = "() => window.__c2rvizPlayer ? window.__c2rvizPlayer.state() : null"
POSES = """() => {
  const m = window.__viserMutable, out = {};
  for (const [n, p] of Object.entries(m ? m.nodePoseData : {})) {
    if (n.startsWith(NODE) && (LINK_NODE)(n)) out[n] = [...p.wxyz, ...p.position];
  }
  return out;
}""".replace("LINK_NODE", LINK_NODE_JS).replace("NODE", repr(LINKS))
MARKERS = """() => {
  const tree = window.__viserSceneTree ? window.__viserSceneTree.getState() : {};
  let count = 0;
  for (const [name, node] of Object.entries(tree)) {
    const at = name.startsWith("/markers/") && node.visibility !== false
      && node?.message?.props?.batched_positions;
    count += at ? at.byteLength / 12 : 0;
  }
  return count;
}"""


def record(server: ServerThread, connect: Any, folder: Path) -> None:
    """``take``: two moves, three marks (one between them), a clear, one more mark."""
    server.call(lambda: setattr(server.services.recordings, "folder", folder))
    client = connect(server)
    for line in (
        "record take",
        "degrees",
        "motion on",
        "speed 100",
        "j 90,45,0,-30,0,60,0",
        "mark",
        "marker cube",
        "mark",
        "j -45,20,30,0,0,-30,0",
        "mark",
        "clear",
        "j 0,30,0,-30,0,40,0",
        "mark",
        "sleep 0.2",
        "record stop",
    ):
        assert client.ask(line).startswith("ok"), line


@pytest.fixture(scope="module")
def take(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[Path, RobotState]]:
    """One recording of ``record`` for the module's tests (they only read it, or damage a
    copy): its folder, and the world's state after it (to write a damaged copy's page)."""
    folder = tmp_path_factory.mktemp("take")
    server = ServerThread(load_robot(), ServerLimits(), clock=VirtualClock()).start()
    clients: list[Client] = []

    def connect(server: ServerThread) -> Client:
        clients.append(Client(server.host, server.port))
        return clients[-1]

    try:
        record(server, connect, folder)
        yield folder, server.world.state()
    finally:
        for client in clients:
            client.close()
        server.stop()


def copy_of(take: tuple[Path, RobotState], folder: Path) -> Path:
    """The recording's files in ``folder`` (a test's own ``tmp_path``)."""
    for name in ("take.csv", "take.txt", "take.html"):
        shutil.copy(take[0] / name, folder / name)
    return folder


def csv_rows(path: Path) -> np.ndarray:
    with open(path, newline="") as file:
        return np.array(list(csv.reader(file))[1:], dtype=float)


def kept_frames(times: np.ndarray) -> np.ndarray:
    """The CSV rows the page keeps: the first of each ``1 / HTML_HZ`` of the recording (of
    each ``end / MAX_HTML_FRAMES`` for a long one), and the last."""
    step = max(1 / HTML_HZ, times[-1] / MAX_HTML_FRAMES)
    bins = np.floor(times / step)
    first = np.flatnonzero(np.diff(bins, prepend=-np.inf) != 0)
    return np.union1d(first, [len(times) - 1])


def shows(poses: dict[str, list[float]], q: Any, tol: float = 2e-5) -> bool:
    """The page's link poses are those of ``q`` [rad] (float32 frames: a few 1e-6 apart)."""
    robot = load_robot()
    poses = in_root(poses)  # the page nests each link's frame in its parent's
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, robot.configuration(q))
    for link in robot.link_names():
        placement = data.oMf[robot.model.getFrameId(link, pin.BODY)]
        x, y, z, w = pin.Quaternion(placement.rotation).coeffs()
        got = np.asarray(poses.get(LINKS + link, [np.nan] * 7))
        wxyz = np.array([w, x, y, z])
        if not np.allclose(got[4:], placement.translation, atol=tol):
            return False
        if not (np.allclose(got[:4], wxyz, atol=tol) or np.allclose(got[:4], -wxyz, atol=tol)):
            return False
    return True


def open_recording(browser: Any, path: Path) -> Any:
    page = browser.new_page(viewport={"width": 1100, "height": 760})
    page.goto(path.as_uri())
    wait_until(lambda: ((s := page.evaluate(STATE)) is not None and s["ready"], s), "the player")
    return page


def test_the_recorded_page_seeks_forward_and_back_to_the_csvs_frames(
    take: tuple[Path, RobotState], tmp_path: Path, browser: Any
) -> None:
    copy_of(take, tmp_path)
    rows = csv_rows(tmp_path / "take.csv")
    page = open_recording(browser, tmp_path / "take.html")
    end = rows[-1, 0]
    assert page.evaluate(STATE)["endS"] == pytest.approx(end, abs=0.5)
    txt = (tmp_path / "take.txt").read_text().splitlines()
    # the marker count at a time, from NAME.txt: marks since the last clear (the first
    # line's clear is the recording's start)
    times, t, count, counts = [], 0.0, 0, []
    for line in txt:
        if line.startswith("sleep "):
            t += float(line.split()[1])
        elif line.startswith("mark "):
            count += 1
            times.append(t)
            counts.append(count)
        elif line == "clear":
            count = 0
            times.append(t)
            counts.append(0)
    kept = kept_frames(rows[:, 0])
    for seconds in (end * 0.8, end * 0.3, end * 0.55, 0.1, end):  # back, on, back, the end
        assert page.evaluate(f"window.__c2rvizPlayer.seek({seconds})") is True
        k = int(np.searchsorted(rows[:, 0], seconds, side="right")) - 1
        state = wait_until(
            lambda t=seconds: ((s := page.evaluate(STATE))["time"] == t == s["plotCursor"], s),
            f"the player at {seconds:.3f} s",
        )
        # the page's frame is a frame of the CSV at or before the time shown: the last one
        # it kept (the first of each 1/30 s, and the last) at or before that time, whatever
        # gaps a busy machine left between the CSV's frames; the arm is posed exactly so
        shown = np.asarray(state["q"])
        frame = np.flatnonzero(np.isclose(rows[:, 1:8], shown, atol=1e-6).all(axis=1))
        assert len(frame) and rows[frame[0], 0] <= seconds + 1e-9
        expected = kept[max(int(np.searchsorted(rows[kept, 0], seconds, side="right")) - 1, 0)]
        assert state["frameTime"] == pytest.approx(rows[expected, 0], abs=1e-9), (seconds, k)
        np.testing.assert_allclose(shown, rows[expected, 1:8], atol=1e-6)
        wait_until(lambda q=shown: (shows(page.evaluate(POSES), q), None), "the arm posed")
        marks = counts[int(np.searchsorted(times, seconds, side="right")) - 1] if times else 0
        wait_until(lambda m=marks: ((n := page.evaluate(MARKERS)) == m, n), f"{marks} markers")
    page.screenshot(path=str(ARTIFACTS / "recorded-page.png"))


def test_the_recorded_pages_controls_step_speed_and_refuse_what_is_out_of_range(
    take: tuple[Path, RobotState], tmp_path: Path, browser: Any
) -> None:
    copy_of(take, tmp_path)
    page = open_recording(browser, tmp_path / "take.html")
    page.evaluate("window.__c2rvizPlayer.seek(1.0)")
    frame = page.evaluate(STATE)["frame"]
    page.get_by_role("button", name="\u25b6", exact=True).click()  # a frame on
    wait_until(lambda: ((s := page.evaluate(STATE))["frame"] == frame + 1, s), "a frame on")
    page.get_by_role("button", name="\u25c0", exact=True).click()  # and back
    wait_until(lambda: ((s := page.evaluate(STATE))["frame"] == frame, s), "a frame back")
    page.select_option("select[aria-label=speed]", "0.25")
    assert page.evaluate(STATE)["speed"] == 0.25
    assert page.evaluate("window.__c2rvizPlayer.setSpeed(3)") is False  # not a speed offered
    time_box = page.locator("input[aria-label='time shown [s]']")
    for bad in ("abc", "1e9", "-2"):
        before = page.evaluate(STATE)
        time_box.fill(bad)
        time_box.press("Enter")
        wait_until(lambda r=before["refused"]: (page.evaluate(STATE)["refused"] > r, None), bad)
        assert page.evaluate(STATE)["time"] == before["time"]
        assert float(time_box.input_value()) == pytest.approx(before["time"], abs=1e-3)
    window_box = page.locator("input[aria-label='plot window [s]']")
    window_box.fill("500")
    window_box.press("Enter")
    wait_until(lambda: (window_box.input_value() == "20", window_box.input_value()), "20 again")
    page.get_by_role("button", name="play", exact=True).click()
    wait_until(lambda: ((s := page.evaluate(STATE))["time"] > 1.05, s), "playing at 0.25x")


@pytest.mark.parametrize(
    ("damage", "message"),
    [
        ("cut", "take.csv line"),
        ("other", "take.csv's last frame is not take.txt's last joints"),
    ],
)
def test_a_damaged_recording_opens_with_its_message(
    take: tuple[Path, RobotState], tmp_path: Path, browser: Any, damage: str, message: str
) -> None:
    from c2rviz.observers.recorder import Recorded
    from c2rviz.view.record_page import write_html

    copy_of(take, tmp_path)
    csv_path, txt = tmp_path / "take.csv", tmp_path / "take.txt"
    if damage == "cut":  # a crash mid-write: the CSV ends in half a row
        text = csv_path.read_text()
        csv_path.write_text(text[: len(text) * 2 // 3])
    else:  # NAME.txt of another run
        body = txt.read_text()
        body = "\n".join(line for line in body.splitlines() if not line.startswith("# recorded"))
        txt.write_text(body.replace("joints 0.0,", "joints 0.5,") + "\njoints 1,1,1,1,1,1,1\n")
    state = take[1]
    recorded = Recorded("take", state.robot.name, txt, csv_path, 0, 0.0, None, ())  # type: ignore[arg-type]
    write_html(recorded, state)
    page = open_recording(browser, tmp_path / "take.html")
    banner = page.locator("#c2rviz-problems")
    wait_until(lambda: (banner.is_visible(), None), "the message")
    assert message in banner.inner_text()
    assert page.evaluate(STATE)["frames"] > 0  # what was good plays
