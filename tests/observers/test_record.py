"""Record and replay through real servers, and the trail.

A session of two clients (one moving in `motion on`, one dropping markers) is recorded,
then NAME.txt is played with c2rviz-play against a fresh server: the final state and
the markers match, and every state a `watch` saw during the replay is a recorded frame,
in order, never ahead of its recorded time. A write error stops the recording with one
warning and an `event record-stopped`, and the server goes on.
"""

from __future__ import annotations

import csv
import logging
import math
import os
import re
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from support import Client, ServerThread, load_robot
from watch_support import STATE, is_reply, read_until

from c2rviz.app.cli import main
from c2rviz.app.config import load_settings
from c2rviz.clients import player
from c2rviz.errors import ConfigError
from c2rviz.observers.recorder import Recorder
from c2rviz.observers.trail import DEFAULT_TRAIL_POINTS, TrailKeeper
from c2rviz.world.world import World

FAR = "90,45,0,-30,0,60,0"  # degrees, motoman_sia20d
OTHER = "-45,20,30,0,0,-30,0"
FRAME_S = 0.01  # the world's frame at the default 100 Hz


def record_into(server: ServerThread, folder: Path) -> None:
    server.call(lambda: setattr(server.services.recordings, "folder", folder))


def markers(server: ServerThread) -> list[tuple]:
    return server.call(lambda: [(m.position, m.wxyz, m.rgb, m.shape) for m in server.world.markers])


def record_two_clients(server: ServerThread, connect, folder: Path) -> tuple[str, list[str]]:
    """Record a mover and a marker-dropper as ``take``; return the final `where` (radians)
    and the two clients' sources."""
    record_into(server, folder)
    boss, mover, dropper = connect(server), connect(server), connect(server)
    assert boss.ask("record take") == f"ok recording take into {folder.resolve()}"
    for line in ("degrees", "motion on", "speed 100"):
        assert mover.ask(line) == "ok"
    mover.send(f"j {FAR}\n")  # the reply comes on arrival
    for line in ("sleep 0.3", "mark", "color 0,0.5,1", "sleep 0.3", "mark", "marker cube"):
        assert dropper.ask(line) == "ok"
    assert mover.read_line() == "ok"
    assert dropper.ask("mark 0.5,0.25,1,0.1,0.2,0.3") == "ok"
    assert mover.ask(f"j {OTHER}") == "ok"
    assert dropper.ask("mark") == "ok"
    assert boss.ask("sleep 0.2") == "ok"
    final = boss.ask("where")
    reply = boss.ask("record stop")
    assert re.fullmatch(
        r"ok recorded take: \d+ frames, \d+\.\d{3} s "
        r"\(.*take\.txt, .*take\.csv, .*take\.html, .*take\)",
        reply,
    )
    sources = [f"tcp 127.0.0.1:{c.sock.getsockname()[1]}" for c in (boss, mover, dropper)]
    return final, sources


def read_frames(path: Path) -> tuple[list[str], np.ndarray]:
    with open(path, newline="") as file:
        rows = list(csv.reader(file))
    return rows[0], np.array(rows[1:], dtype=float)


@pytest.mark.wall_clock
def test_a_recorded_session_replays_to_the_same_states(
    start_server, connect, tmp_path: Path, capsys
):
    first = start_server()
    final, sources = record_two_clients(first, connect, tmp_path)
    recorded_markers = markers(first)
    assert len(recorded_markers) == 4
    txt, table = tmp_path / "take.txt", tmp_path / "take.csv"
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "take",
        "take.csv",
        "take.html",
        "take.txt",
    ]

    # The command file: its header, then commands the player takes.
    text = txt.read_text()
    head = [line for line in text.splitlines() if line.startswith("#")]
    assert head[1] == "# robot: motoman_sia20d"
    assert head[2].startswith("# recorded: ")
    assert all(source in head[3] for source in sources), head[3]
    script = player.load_script(txt)
    assert script.problems == [] and script.robot == "motoman_sia20d"
    verbs = [line.wire.split()[0] for line in script.lines]
    assert verbs[:3] == ["radians", "motion", "clear"]
    assert verbs.count("mark") == 4 and verbs.count("marker") == 1 and verbs.count("color") == 1

    # The frames: one row per `joints` line of the file, at most one per frame.
    header, frames = read_frames(table)
    names = load_robot().joint_names
    assert header == ["time", *names, "x", "y", "z", "roll", "pitch", "yaw"]
    joints_lines = [line.wire for line in script.lines if line.wire.startswith("joints")]
    assert len(frames) == len(joints_lines) > 100  # the moves took over a second each
    robot = load_robot()
    for line, row in zip(joints_lines, frames):  # the file exact, the table to 10 digits
        exact = [float(v) for v in line.split()[1].split(",")]
        assert row[1:8] == pytest.approx(exact, rel=1e-9, abs=1e-9)
    with open(table, newline="") as file:
        raw = list(csv.reader(file))[1:]
    assert all(v == "0" or v == f"{float(v):.10g}" for row in raw for v in row[1:])  # short
    assert (np.diff(frames[:, 0]) >= FRAME_S - 1e-6).all()
    for line, row in list(zip(joints_lines, frames))[:: len(frames) // 10]:
        pose = robot.ee_pose([float(v) for v in line.split()[1].split(",")])
        expected = [*pose.translation, *pin.rpy.matrixToRpy(pose.rotation)]
        np.testing.assert_allclose(row[8:], expected, rtol=1e-9, atol=1e-9)
    assert ",".join(f"{v:.10g}" for v in frames[-1, 1:8]) == ",".join(
        f"{v:.10g}" for v in map(float, final[3:].split(","))
    )

    # Played against a fresh server, watched all along.
    second = start_server()
    watcher = connect(second)
    assert watcher.ask("watch 1000") == "ok"
    seen: list[str] = []
    reader = threading.Thread(target=read_until, args=(watcher, is_reply, seen))
    reader.start()
    assert player.main([str(txt), "--port", str(second.port)]) == 0
    watcher.send("where\n")
    reader.join(timeout=30)
    assert seen[-1] == final  # the watcher's own `where`, after every stream line
    checker = connect(second)
    assert checker.ask("where") == final
    for got, want in zip(markers(second), recorded_markers, strict=True):
        np.testing.assert_allclose(got[0], want[0], atol=1e-12)
        np.testing.assert_allclose(np.abs(np.dot(got[1], want[1])), 1.0, atol=1e-12)
        assert got[2:] == want[2:]

    # Every state the watcher saw is a recorded frame, in the recorded order, and none
    # came ahead of its recorded time (aligned on the first state after home).
    watched = [
        (float(m.group(1)), np.array(m.group(2).split(","), dtype=float))
        for m in map(STATE.fullmatch, seen)
        if m
    ]
    k = 0
    matched = []
    for t, q in watched:
        while k < len(frames) and not np.allclose(frames[k, 1:8], q, rtol=0, atol=1e-9):
            k += 1
        assert k < len(frames), f"state at {t} is no recorded frame (or out of order)"
        matched.append((t, frames[k, 0]))
    moving = [(t, r) for t, r in matched if r > 0]
    assert len(moving) > 50
    # Aligned on the replay's first state (before any sleep: no timer can make it late).
    # Not on the first moving one: it comes after a sleep, and the server's sleeps keep
    # the script's schedule (a late timer does not push the next), so one late first move
    # would make the on-time moves after it look early (seen at load 10).
    offset = matched[0][0] - matched[0][1]
    assert matched[0][1] < moving[0][1]
    assert all(t - offset >= r - FRAME_S for t, r in moving)
    # How late the replay ran is a figure of the machine (printed); that late timers do
    # not add up across a script's sleeps is tests/world/test_clock.py's, on a clock whose
    # timers are late by a known amount (a 0.25 s bound here failed at a load of 6-8).
    late = [t - offset - r for t, r in moving]
    print(
        f"replay: {len(moving)} states, latest {max(late) * 1e3:.1f} ms late, last {late[-1]:.3f} s"
    )


def test_record_status_and_bad_names(server: ServerThread, connect, tmp_path: Path):
    record_into(server, tmp_path)
    client = connect(server)
    assert client.ask("record") == "ok not recording"
    assert client.ask("record stop") == "error: record: nothing is being recorded"
    bad = "error: record: bad name"
    assert client.ask("record ../x").startswith(bad + " '../x'")
    assert client.ask("record a/b").startswith(bad + " 'a/b'")
    assert client.ask("record .x").startswith(bad)
    assert client.ask("record one") == f"ok recording one into {tmp_path.resolve()}"
    assert re.fullmatch(r"ok recording one \d+\.\d{3}", client.ask("record"))
    assert client.ask("record two").startswith("error: record: one is being recorded (")
    assert client.ask("record stop").startswith("ok recorded one: ")
    assert client.ask("record one") == (
        f"error: record: one already exists in {tmp_path}; choose another name or say "
        "'record one overwrite'"
    )
    assert client.ask("record one overwrite").startswith("ok recording one")
    assert client.ask("record stop").startswith("ok recorded one: ")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["one", "one.csv", "one.html", "one.txt"]
    assert not (tmp_path.parent / "x.txt").exists()


def test_a_write_error_stops_the_recording_and_the_server_goes_on(
    server: ServerThread, connect, tmp_path: Path, caplog
):
    record_into(server, tmp_path)
    watcher, client = connect(server), connect(server)
    assert watcher.ask("watch 1") == "ok"
    assert client.ask("record broken") == f"ok recording broken into {tmp_path.resolve()}"

    def break_the_files() -> None:
        recorder = server.services.recordings.current
        assert recorder is not None
        read_only = os.open(os.devnull, os.O_RDONLY)
        for file in (recorder._body, recorder._rows):  # as if the disk went away
            os.dup2(read_only, file.fileno())
        os.close(read_only)

    server.call(break_the_files)
    seen: list[str] = []
    with caplog.at_level(logging.WARNING, logger="c2rviz.recorder"):
        # Frames over more than a second of the clock: the buffered files are flushed.
        client.send("".join(f"move 0 {k / 1000}\nsleep 0.02\n" for k in range(100)))
        read_until(watcher, lambda line: line.startswith("event record-stopped"), seen)
        for _ in range(200):
            assert client.read_line() == "ok"
    assert re.fullmatch(r"event record-stopped broken: write error: .+", seen[-1])
    warnings = [r for r in caplog.records if r.name == "c2rviz.recorder"]
    assert len(warnings) == 1 and "recording broken stopped by a write error" in warnings[0].message
    assert client.ask("record") == "ok not recording"
    assert client.ask("where") == "ok 0.099,0,0,0,0,0,0"
    assert client.ask("record stop") == "error: record: nothing is being recorded"
    # What was written is kept, each file ending with a whole line, in place.
    deadline = time.monotonic() + 60
    while (
        time.monotonic() < deadline and server.call(lambda: server.services.recordings.last) is None
    ):
        time.sleep(0.05)
    txt = tmp_path / "broken.txt"
    script = player.load_script(txt)
    assert script.problems == [] and script.robot == "motoman_sia20d"
    assert "# stopped early: write error: " in txt.read_text()
    rows = (tmp_path / "broken.csv").read_text()  # what was flushed before the disk went
    assert rows == "" or rows.endswith("\n")
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "broken",
        "broken.csv",
        "broken.html",
        "broken.txt",
    ]


def test_watchers_hear_when_a_recording_stops(server: ServerThread, connect, tmp_path: Path):
    record_into(server, tmp_path)
    watcher, client = connect(server), connect(server)
    assert watcher.ask("watch") == "ok"
    assert client.ask("record quick").startswith("ok recording quick")
    assert client.ask("record stop").startswith("ok recorded quick: 1 frame, ")
    seen: list[str] = []
    read_until(watcher, lambda line: line.startswith("event"), seen)
    port = client.sock.getsockname()[1]
    assert seen[-1] == f"event record-stopped quick: stopped by tcp 127.0.0.1:{port}"


def test_record_flag_records_from_start_to_exit(c2rviz_process, tmp_path: Path, capsys):
    proc = c2rviz_process("--no-viewer", "--record", "run", "--record-dir", str(tmp_path))
    client = Client("127.0.0.1", proc.port)
    try:
        assert client.ask("record").startswith("ok recording run ")
        assert client.ask("move 0 0.5") == "ok"
        assert client.ask("quit") == "ok"
    finally:
        client.close()
    assert proc.wait() == 0
    output = proc.popen.stdout.read()  # type: ignore[union-attr]
    assert f"c2rviz: recorded run: 2 frames, {tmp_path / 'run.txt'}" in output
    lines = (tmp_path / "run.txt").read_text().splitlines()
    assert [line for line in lines if line.startswith("joints")][-1] == (
        "joints 0.5,0.0,0.0,0.0,0.0,0.0,0.0"
    )
    # An existing name is refused, before anything starts: so in this process (the
    # status `python -m c2rviz` exits with is main's).
    again = main(["--no-viewer", "--port", "0", "--record", "run", "--record-dir", str(tmp_path)])
    assert again == 2
    assert "record: run already exists in" in capsys.readouterr().err


def test_a_cell_member_records_its_tool_pose_and_marks_in_its_base_frame(tmp_path: Path):
    """A robot away from the cell's origin, with a tool: NAME.csv has the tool's pose and
    NAME.txt's `mark` lines the base-frame poses the robot's own client would send."""
    robot = load_robot()
    origin = pin.SE3(pin.rpy.rpyToMatrix(0.0, 0.0, 0.5), np.array([1.0, -0.5, 0.2]))
    world = World({"b": robot}, origins={"b": origin})
    tool_offset = pin.SE3(pin.rpy.rpyToMatrix(0.0, 0.4, 0.0), np.array([0.0, 0.02, 0.1]))
    world.set_tool("b", tool_offset)
    recorder = Recorder(world, "b", "cell", tmp_path, on_failed=lambda *_: None)
    world.add_observers([recorder])
    pose = pin.SE3(pin.rpy.rpyToMatrix(0.1, 0.2, 0.3), np.array([0.5, 0.25, 1.0]))
    world.add_marker(pose, (1.0, 0.0, 0.0), "sphere", robot="b")
    recorder.stop()
    recorded = recorder.finish()
    assert recorded.txt is not None
    (mark,) = [line for line in recorded.txt.read_text().splitlines() if line.startswith("mark")]
    np.testing.assert_allclose(
        [float(v) for v in mark.split()[1].split(",")],
        [*pose.translation, *pin.rpy.matrixToRpy(pose.rotation)],
        atol=1e-9,
    )
    _header, frames = read_frames(recorded.csv)
    at_home = robot.ee_pose(robot.home) * tool_offset
    np.testing.assert_allclose(
        frames[0, 8:], [*at_home.translation, *pin.rpy.matrixToRpy(at_home.rotation)], atol=1e-9
    )


# --- the trail ---------------------------------------------------------------------------


def test_the_trail_follows_the_tool_along_a_move(server: ServerThread, connect):
    client = connect(server)
    assert client.ask("tool 0,0.05,0.1,0,0,0") == "ok"  # the tool point, off the flange
    offset = pin.SE3(np.eye(3), np.array([0.0, 0.05, 0.1]))
    assert client.ask("trail") == "ok off"
    assert client.ask("trail on") == "ok"
    assert client.ask("trail") == "ok on 1"
    start = server.call(lambda: len(server.scene.joints))
    for line in ("degrees", "motion on", "speed 100", f"j {FAR}"):
        assert client.ask(line) == "ok"
    robot = load_robot()
    frames = server.call(lambda: list(server.scene.joints[start:]))
    along = np.array(
        [(robot.base_placement * robot.ee_pose(q) * offset).translation for q in frames]
    )
    keeper = server.services.trails
    points = server.call(keeper.points, "motoman_sia20d")
    assert len(points) > 50  # at frame rate, not only the targets
    home = (robot.base_placement * robot.ee_pose(robot.home) * offset).translation
    np.testing.assert_allclose(points[0], home)
    np.testing.assert_allclose(points[-1], along[-1])
    for point in points[1:]:  # every point is where the tool was in a published frame
        assert np.min(np.linalg.norm(along - point, axis=1)) < 1e-12
    assert client.ask("trail") == f"ok on {len(points)}"
    segments = server.call(keeper.segments, "motoman_sia20d")
    assert segments.shape == (len(points) - 1, 2, 3)
    assert client.ask("trail clear") == "ok"
    assert client.ask("trail") == "ok on 1"
    assert client.ask("trail off") == "ok"
    assert client.ask("trail") == "ok off"
    assert server.call(lambda: keeper not in server.world.observers)
    assert client.ask("trail sideways").startswith("error: trail: unknown action 'sideways'")


def a_world() -> World:
    """A world of its own (no server): the trail's effects are called directly."""
    return World(load_robot())


def tool(q) -> np.ndarray:
    robot = load_robot()
    return (robot.base_placement * robot.ee_pose(q)).translation


def test_the_trail_stays_within_its_cap_and_keeps_its_extent():
    world = a_world()
    keeper = TrailKeeper(world)
    keeper.start("motoman_sia20d")
    first = keeper.points("motoman_sia20d")[0]
    t0 = world.clock.now() + 100
    most = 0
    for k in range(100_000):  # 100k frames, each a new place
        q = (0.5 * math.sin(k / 5000), 0.3 * math.sin(k / 777), 0, 0, 0, 0, 0)
        keeper.on_joints("motoman_sia20d", q, t0 + k * FRAME_S)
        if k % 1000 == 0:
            most = max(most, len(keeper.trails["motoman_sia20d"]))
    points = keeper.points("motoman_sia20d")
    assert DEFAULT_TRAIL_POINTS // 2 < len(points) <= DEFAULT_TRAIL_POINTS
    assert most <= DEFAULT_TRAIL_POINTS
    assert keeper.changed > 100_000
    np.testing.assert_array_equal(points[0], first)  # thinning keeps the oldest point
    np.testing.assert_allclose(points[-1], tool(q))  # and the newest


def test_a_flood_adds_one_trail_point_per_frame():
    world = a_world()
    keeper = TrailKeeper(world)
    keeper.start("motoman_sia20d")
    t0 = world.clock.now() + 100
    for k in range(1000):  # 1000 states within 0.1 s: ten frames
        keeper.on_joints("motoman_sia20d", (0, (k + 1) / 1000, 0, 0, 0, 0, 0), t0 + k * 1e-4)
    points = keeper.points("motoman_sia20d")
    assert len(points) == 1 + 10 + 1  # the start, a point per frame, the latest
    np.testing.assert_allclose(points[-1], tool((0, 1.0, 0, 0, 0, 0, 0)))


@pytest.mark.parametrize("cap", [16, 17, 1000])
def test_thinning_at_any_cap(cap: int):
    world = a_world()
    keeper = TrailKeeper(world, cap)
    keeper.start("motoman_sia20d")
    t0 = world.clock.now() + 100
    sizes = []
    for k in range(10 * cap):
        q = (0, (k + 1) / (10 * cap), 0, 0, 0, 0, 0)  # the tool swings forward
        keeper.on_joints("motoman_sia20d", q, t0 + k)
        sizes.append(len(keeper.trails["motoman_sia20d"]))
    assert max(sizes) == cap and min(sizes[cap:]) >= cap // 2
    points = keeper.points("motoman_sia20d")
    np.testing.assert_allclose(points[-1], tool(q))
    assert (np.diff(points[:, 0]) > 0).all()  # in order, no repeats
    keeper.stop("motoman_sia20d")
    assert len(keeper.points("motoman_sia20d")) == 0 and keeper not in world.observers
    with pytest.raises(ValueError, match="at least 16 points"):
        TrailKeeper(world, 15)


def test_settings_for_recordings_and_trails(tmp_path: Path):
    ini = tmp_path / "c2rviz.ini"
    ini.write_text("[options]\nrecord_dir = takes\ntrail_points = 500\n")
    settings = load_settings(ini, {"urdf": ini})
    assert settings.record_dir == tmp_path / "takes"  # relative to the ini file
    assert settings.trail_points == 500 and settings.record is None
    flags = load_settings(ini, {"urdf": ini, "record_dir": "here", "record": "x"})
    assert flags.record_dir == Path("here") and flags.record == "x"
    assert load_settings(None, {"urdf": ini}).record_dir == Path("recordings")
    ini.write_text("[options]\ntrail_points = 5\n")
    with pytest.raises(ConfigError, match="trail_points = 5 is outside 16..1e"):
        load_settings(ini, {"urdf": ini})


@pytest.mark.parametrize(
    ("name", "message"),
    [("../x", "bad name '../x'"), ("stop", "--record needs a name; 'stop' is not one")],
)
def test_record_flag_refuses_a_bad_name(tmp_path: Path, name: str, message: str, capsys):
    """Refused before anything starts: main in this process, its status the program's."""
    status = main(["--no-viewer", "--port", "0", "--record", name, "--record-dir", str(tmp_path)])
    assert status == 2 and message in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


# The markers the recorded page holds: instances of its batched marker nodes.
RECORDED_MARKERS = """() => {
  const tree = window.__viserSceneTree;
  if (!tree) return null;
  let count = 0;
  for (const [name, node] of Object.entries(tree.getState())) {
    const at = name.startsWith("/markers/") && node?.message?.props?.batched_positions;
    count += at ? at.byteLength / 12 : 0;
  }
  return count;
}"""


@pytest.mark.browser
@pytest.mark.wall_clock
def test_the_recorded_page_plays_in_a_browser_without_a_server(
    start_server, connect, tmp_path: Path, browser
):
    """NAME.html opens from a file:// URL in headless Chromium, the robot moves and the
    recorded markers appear."""
    from browser_support import changed, wait_until
    from PIL import Image

    record_two_clients(start_server(), connect, tmp_path)
    page_file = tmp_path / "take.html"
    text = page_file.read_text()
    assert text.startswith("<!") and "ws://" not in text.split("<script", 1)[0]

    def shot(page) -> np.ndarray:  # type: ignore[no-untyped-def]
        import io

        picture = Image.open(io.BytesIO(page.screenshot())).convert("RGB")
        return np.asarray(picture, dtype=np.int16)[100:560, 200:800]

    page = browser.new_page(viewport={"width": 1000, "height": 700})
    page.goto(page_file.as_uri())
    first = shot(page)
    # The recorded arm swings over about two seconds: the picture changes as it plays.
    wait_until(lambda: (changed(first, shot(page)) > 500, None), "the recording playing")
    # The four markers dropped during the run are there by its end.
    wait_until(lambda: ((n := page.evaluate(RECORDED_MARKERS)) == 4, n), "the recorded markers")


@pytest.mark.xdist_group("default_ports")  # binds a default port: one at a time
def test_recordings_land_in_the_working_directory_by_default(tmp_path: Path):
    """Issue 30.3: started from an empty folder (the project's ini is read), `record demo`
    writes ./recordings/demo.txt there, not into the project's folder."""
    import os
    import signal

    proc = subprocess.Popen(
        [sys.executable, "-m", "c2rviz", "--no-viewer", "--port", "0"],
        cwd=tmp_path,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        env={**os.environ, "PYTHONUNBUFFERED": "1"},
    )
    assert proc.stdout is not None
    try:
        port = None
        while port is None:
            line = proc.stdout.readline()
            assert line, "c2rviz stopped"
            if m := re.search(r"commands on [\d.]+:(\d+)", line):
                port = int(m.group(1))
        client = Client("127.0.0.1", port)
        where = (tmp_path / "recordings").resolve()
        assert client.ask("record demo") == f"ok recording demo into {where}"
        assert client.ask("record stop").startswith("ok recorded demo")
        client.close()
        assert (tmp_path / "recordings" / "demo.txt").is_file()
    finally:
        proc.send_signal(signal.SIGTERM)
        proc.wait(timeout=60)
        proc.stdout.close()
