"""The page as an instrument in a real headless Chromium, the whole program behind it.

The charts are read from the page's uPlot instances (viser's test hooks:
``__viserTestpoints.uplots``), the arm from the poses the page applies to its link
nodes, and both are compared with Pinocchio's forward kinematics of what the
program said (``where``, a ``watch`` stream, NAME.csv). Waits are on signals.
"""

from __future__ import annotations

import csv
import math
import socket
from typing import Any

import numpy as np
import pinocchio as pin
import pytest
from browser_support import (
    ARTIFACTS,
    LINK_NODE_JS,
    LastingProgram,
    Tcp,
    field,
    in_root,
    page_state,
    slider_input,
    wait_until,
)
from support import load_robot

pytestmark = pytest.mark.browser

ROBOT = "motoman_sia20d"
LINKS = f"/robots/{ROBOT}/links/"

# Every chart's data, by its first series' label ("joint_s" for the joints and velocities,
# "tool m/s" for the tool's speed), and the frame counter: one snapshot of the page.
CHARTS = """() => {
  const charts = (window.__viserTestpoints || {}).uplots || {};
  const out = {};
  for (const entry of Object.values(charts)) {
    const chart = entry.chart;
    const title = chart.root.querySelector(".u-title")?.textContent || "";
    out[title] = chart.data.map((series) => Array.from(series.slice(-3)));
  }
  const m = window.__viserMutable, tp = window.__viserTestpoints;
  const poses = {};
  for (const [n, p] of Object.entries(m ? m.nodePoseData : {})) {
    if (n.startsWith(NODE) && (LINK_NODE)(n)) poses[n] = [...p.wxyz, ...p.position];
  }
  return {charts: out, poses, frame: tp ? tp.rendererInfo.render.frame : 0};
}""".replace("LINK_NODE", LINK_NODE_JS).replace("NODE", repr(LINKS))
VISIBILITY = """(names) => {
  const tree = window.__viserSceneTree ? window.__viserSceneTree.getState() : {};
  return names.map((n) => (tree[n] === undefined ? null : tree[n].visibility !== false));
}"""


def expected_poses(q: Any) -> dict[str, np.ndarray]:
    """Each link node's pose (w, x, y, z, px, py, pz) for chain values ``q`` [rad]."""
    robot = load_robot(ROBOT)
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, robot.configuration(q))
    out = {}
    for link in robot.link_names():
        placement = data.oMf[robot.model.getFrameId(link, pin.BODY)]
        x, y, z, w = pin.Quaternion(placement.rotation).coeffs()
        out[LINKS + link] = np.array([w, x, y, z, *placement.translation])
    return out


def shows(poses: dict[str, list[float]], q: Any, tol: float = 1e-5) -> bool:
    """Whether the page's link poses are those of ``q`` (a quaternion and its negative agree)."""
    poses = in_root(poses)  # the page nests each link's frame in its parent's
    for name, want in expected_poses(q).items():
        got = np.asarray(poses.get(name, [np.nan] * 7))
        if not np.allclose(got[4:], want[4:], atol=tol):
            return False
        if not (
            np.allclose(got[:4], want[:4], atol=tol) or np.allclose(got[:4], -want[:4], atol=tol)
        ):
            return False
    return True


def brief(snapshot: dict[str, Any]) -> dict[str, Any]:
    """What a wait reports of a snapshot: the frame, each chart's last x and joint_s value,
    and the arm's first link poses."""
    charts = {k: [round(v[-1], 3) for v in series[:2]] for k, series in snapshot["charts"].items()}
    links = {k.rsplit("/", 1)[1]: [round(v, 4) for v in p] for k, p in snapshot["poses"].items()}
    return {"frame": snapshot["frame"], "charts": charts, "link_s": links.get("link_s")}


def where(tcp: Tcp) -> list[float]:
    return [float(v) for v in tcp.ask("where")[3:].split(",")]


def test_the_plot_shows_a_joints_command_within_a_frame(
    browser: Any, motoman: LastingProgram
) -> None:
    with motoman.session() as (proc, page, tcp):
        wait_until(lambda: (len(page.evaluate(CHARTS)["charts"]) >= 2, None), "the charts")
        for q in ([0.3, -0.2, 0.1, 0.4, -0.5, 0.3, 0.2], [-0.6, 0.4, -0.3, -0.2, 0.5, -0.1, 0.0]):
            assert tcp.ask("joints " + ",".join(map(str, q))) == "ok"
            seen = wait_until(
                lambda q=q: ((s := page.evaluate(CHARTS)) and shows(s["poses"], q), brief(s)),
                "the arm at the joints sent",
            )
            frame = seen["frame"]
            wait_until(  # one frame later at most, the chart ends there too
                lambda f=frame: (page.evaluate(CHARTS)["frame"] > f, None), "a frame"
            )
            joints = page.evaluate(CHARTS)["charts"]["joints [deg]"]
            assert [series[-1] for series in joints[1:8]] == pytest.approx(np.degrees(q), abs=1e-6)
        page.screenshot(path=str(ARTIFACTS / "instruments-plots.png"))


def test_looking_back_in_the_live_page_shows_the_arm_as_the_csv_has_it(
    browser: Any, own_motoman: LastingProgram
) -> None:
    motoman = own_motoman
    with motoman.session() as (proc, page, tcp):
        # Both closed here: a socket closed while its file is open stays open until the
        # file is collected, and the garbage collector's ResourceWarning then failed
        # whichever test ran next (test_ghost_off_hides_..., at its setup).
        with (
            socket.create_connection(("127.0.0.1", proc.port), timeout=60) as watcher,
            watcher.makefile("rb") as stream,
        ):
            watcher.sendall(b"watch\n")
            assert stream.readline() == b"ok\n"
            for line in ("record take", "degrees", "motion on", "speed 40"):
                assert tcp.ask(line).startswith("ok"), line
            assert tcp.ask("j 90,45,0,-30,0,60,0") == "ok"  # the reply comes on arrival
            assert tcp.ask("record stop").startswith("ok recorded take")
            watcher.sendall(b"unwatch\n")
            states = []  # (T [s since the server started], q [rad]) of every frame of the move
            for raw in iter(stream.readline, b"ok\n"):
                words = raw.decode().split()
                if words[0] == "state":  # the watcher speaks radians
                    q = np.array([float(v) for v in words[2].split(",")])
                    states.append((float(words[1]), q))
        assert len(states) > 50
        with open(motoman.record_dir / "take.csv", newline="") as file:
            rows = np.array(list(csv.reader(file))[1:], dtype=float)[:, 1:8]

        time_box = slider_input(page, "Time s")
        for k in (len(states) * 2 // 3, len(states) // 3, len(states) // 2):  # back, and on
            t = math.floor(states[k][0] * 100) / 100  # the slider's 0.01 s steps
            time_box.fill(f"{t:.2f}")
            time_box.press("Enter")
            # the page shows its latest sample at or before t: one of the last few frames
            # before t (it keeps at most one a frame period; a busy machine spaces them out)
            candidates = [(at, q) for at, q in states if at <= t + 1e-9][-5:]
            wait_until(
                lambda c=candidates: (
                    (s := page.evaluate(CHARTS)) and any(shows(s["poses"], q) for _, q in c),
                    brief(s),
                ),
                f"the page to show the arm at {t:.2f} s",
            )
            poses = page.evaluate(CHARTS)["poses"]
            shown_t, shown = next((at, q) for at, q in candidates if shows(poses, q))
            # the same state is a frame of the recording (NAME.csv, 10 significant digits)
            assert np.isclose(rows, shown, rtol=1e-8, atol=1e-9).all(axis=1).any()
            # the plots' cursor: they end at the sample shown
            wait_until(
                lambda t=shown_t: (
                    abs(page.evaluate(CHARTS)["charts"]["joints [deg]"][0][-1] - t) < 0.005,
                    page.evaluate(CHARTS)["charts"]["joints [deg]"][0],
                ),
                f"the plots to end at {shown_t:.3f} s (the sample shown for {t:.2f} s)",
            )
            assert "s ago" in field(page, "Shown").input_value()
        page.screenshot(path=str(ARTIFACTS / "instruments-look-back.png"))
        page.get_by_role("button", name="live", exact=True).click()
        final = np.radians(where(tcp))
        wait_until(lambda: ((s := page_state(page)) and shows(s["poses"], final), None), "live")
        assert field(page, "Shown").input_value() == "live"


def test_ghost_off_hides_the_ghost_and_path_and_on_shows_them_until_arrival(
    browser: Any, motoman: LastingProgram
) -> None:
    ghost = [f"/robots/{ROBOT}/target", f"/robots/{ROBOT}/path"]
    with motoman.session() as (proc, page, tcp):
        for line in ("degrees", "j 0,40,0,-40,0,60,0", "lspeed 0.04", "motion follow"):
            assert tcp.ask(line) == "ok", line
        pose = [float(v) for v in tcp.ask("pose")[3:].split(",")]
        assert tcp.ask("ghost off") == "ok"
        there = [*pose[:1], pose[1] + 0.2, *pose[2:]]
        assert tcp.ask("movel " + ",".join(map(str, there))) == "ok"  # ~5 s along the line
        assert tcp.ask("status").startswith("ok moving")
        page.wait_for_timeout(500)  # frames of the move are drawn meanwhile
        # neither shown: not drawn yet (None), or hidden (False): an earlier move of the
        # shared program (LastingProgram) may have drawn the target and not a path
        assert set(shown := page.evaluate(VISIBILITY, ghost)) <= {None, False}, shown
        assert tcp.ask("ghost on") == "ok"
        wait_until(
            lambda: ((v := page.evaluate(VISIBILITY, ghost)) == [True, True], v),
            "the ghost and the path line during the move",
        )
        page.screenshot(path=str(ARTIFACTS / "instruments-ghost.png"))
        wait_until(lambda: (tcp.ask("status") == "ok idle", None), "the arrival")
        wait_until(
            lambda: ((v := page.evaluate(VISIBILITY, ghost)) == [False, False], v),
            "the ghost and the path line gone at arrival",
        )
