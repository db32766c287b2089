"""NAME.html built streaming from NAME.csv and NAME.txt: thinned, checked, and honest about a
recording that is cut short or whose files disagree (the browser tests play the pages)."""

from __future__ import annotations

import base64
import dataclasses
import gzip
import json
import math
import re
import tracemalloc
from datetime import datetime, timezone
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from support import ROOT, load_robot

from c2rviz.observers.recorder import Recorded
from c2rviz.robot.model import Robot
from c2rviz.view.record_commands import MAX_HTML_MARKS, read_commands
from c2rviz.view.record_frames import (
    HTML_HZ,
    MAX_HTML_FRAMES,
    chain_kinematics,
    pose_links,
    read_frames,
)
from c2rviz.view.record_page import write_html
from c2rviz.world.state import RobotState

TREE = ROOT / "tests" / "data" / "tree_robot" / "tree.urdf"
POSE = "x,y,z,roll,pitch,yaw"


def header(robot: Robot) -> str:
    return f"time,{','.join(robot.joint_names)},{POSE}\n"


def write_recording(
    folder: Path, robot: Robot, rows: int, hz: float = 100.0, marks: int = 0
) -> tuple[Path, Path]:
    """NAME.csv and NAME.txt as the recorder writes them, for ``rows`` frames of a sine."""
    csv, txt = folder / "take.csv", folder / "take.txt"
    n = robot.n
    with open(csv, "w") as c, open(txt, "w") as t:
        c.write(header(robot))
        t.write(
            "# c2rviz recording take: play it back with c2rviz-play take.txt\n"
            f"# robot: {robot.name}\n"
            f"# recorded: 2026-01-01T00:00:00+00:00, {(rows - 1) / hz:.3f} s, {rows} frames "
            f"(at most {hz:g} a second)\n# sources: test\n# frames: take.csv\n"
            "radians\nmotion off\nclear\n"
        )
        for k in range(rows):
            q = [0.5 * math.sin(k / hz + j) for j in range(n)]
            values = ",".join(repr(v) for v in q)
            if k:
                t.write(f"sleep {1 / hz:g}\n")
            t.write(f"joints {values}\n")
            if k < marks:
                t.write(f"mark 0.5,{k * 1e-3},1,0,0,0\n")
            c.write(f"{k / hz:.6f},{','.join(f'{v:.10g}' for v in q)},0,0,0,0,0,0\n")
    return csv, txt


def recorded(csv: Path, txt: Path | None, robot: Robot) -> Recorded:
    return Recorded("take", robot.name, txt, csv, 0, 0.0, datetime.now(timezone.utc), ())


def page_meta(path: Path) -> dict:
    text = path.read_text()
    found = re.search(r'<script type="application/json" id="c2rviz-recording">(.*?)</script>', text)
    assert found, "the page lost its recording"
    return json.loads(found.group(1))


def page_array(path: Path, name: str, dtype: str) -> np.ndarray:
    text = path.read_text()
    found = re.search(rf'id="c2rviz-{name}">(.*?)</script>', text, re.S)
    assert found
    return np.frombuffer(gzip.decompress(base64.b64decode(found.group(1))), dtype=dtype)


# the chain's kinematics, as the page computes them


@pytest.mark.parametrize("name", ["motoman_sia20d", "fanuc_lrmate200id", "kuka_lwr", "tree"])
def test_the_pages_kinematics_are_pinocchios(name: str) -> None:
    """Mimic and continuous joints too (the tree robot has both)."""
    robot = Robot.from_urdf(TREE, "base_link", "tool0") if name == "tree" else load_robot(name)
    kinematics = json.loads(json.dumps(chain_kinematics(robot)))  # as the page reads them
    rng = np.random.default_rng(5)
    data = robot.model.createData()
    for _ in range(50):
        q = robot.random(rng)
        pin.framesForwardKinematics(robot.model, data, robot.configuration(q))
        for link, pose in zip(robot.link_names(), pose_links(kinematics, q)):
            expected = data.oMf[robot.model.getFrameId(link, pin.BODY)]
            assert pose.isApprox(expected, 1e-9), link


# NAME.csv, streamed


def test_frames_are_thinned_to_what_the_page_shows(tmp_path: Path) -> None:
    robot = load_robot()
    csv, _ = write_recording(tmp_path, robot, 1000)
    frames = read_frames(csv, robot.joint_names)
    assert frames.rows == 1000 and not frames.problems
    assert frames.times[0] == 0.0 and frames.times[-1] == pytest.approx(9.99)  # ends kept
    bins = np.floor(frames.times[:-1] * HTML_HZ)  # at most one frame per 1/HTML_HZ
    assert len(np.unique(bins)) == len(bins)
    assert len(frames.times) <= 9.99 * HTML_HZ + 2
    assert frames.values.shape == (len(frames.times), robot.n + 6)
    assert frames.values[-1, 0] == pytest.approx(0.5 * math.sin(9.99), abs=1e-6)


@pytest.mark.parametrize(
    ("damage", "message", "rows"),
    [
        (lambda text: text[:-20], "line 502 ends in a partial row: the recording was cut", 500),
        (lambda text: text.replace("\n3.000000,", "\n3.000000,nan,", 1), "line 302 has 15", 300),
        (lambda text: text.replace("\n2.000000,", "\n2.000000x,", 1), "not a finite number", 200),
        (lambda text: text.replace("\n4.000000,", "\n1.000000,", 1), "goes back in time", 400),
    ],
    ids=["cut-mid-row", "a-value-too-many", "a-bad-number", "time-goes-back"],
)
def test_a_damaged_csv_keeps_the_good_rows_and_says_where(
    tmp_path: Path, damage, message: str, rows: int
) -> None:
    robot = load_robot()
    csv, _ = write_recording(tmp_path, robot, 501)
    csv.write_text(damage(csv.read_text()))
    frames = read_frames(csv, robot.joint_names)
    assert len(frames.problems) == 1 and re.search(message, frames.problems[0]), frames.problems
    assert frames.rows == rows
    assert f"the {rows} good rows" in frames.problems[0]


def test_another_robots_csv_or_an_empty_one_says_so(tmp_path: Path) -> None:
    robot = load_robot()
    csv, _ = write_recording(tmp_path, load_robot("fanuc_lrmate200id"), 10)
    problems = read_frames(csv, robot.joint_names).problems
    assert problems and "is not this robot's: its columns are time,joint_1" in problems[0]
    csv.write_text("")
    empty = read_frames(csv, robot.joint_names).problems
    assert empty == ["take.csv is empty: nothing was recorded"]
    csv.write_text(header(robot))
    assert read_frames(csv, robot.joint_names).problems == [
        "take.csv holds no frames: nothing was recorded"
    ]


def test_reading_streams_its_memory_does_not_grow_with_the_file(tmp_path: Path) -> None:
    """The same 2000 s at 50 and at 100 rows a second: the page keeps the same frames, and
    reading twice the file costs no more memory."""
    robot = load_robot()
    peaks, sizes = [], []
    for rows, hz in ((100_000, 50.0), (200_000, 100.0)):
        folder = tmp_path / str(rows)
        folder.mkdir()
        csv, txt = write_recording(folder, robot, rows, hz=hz, marks=3)
        sizes.append(csv.stat().st_size + txt.stat().st_size)
        tracemalloc.start()
        try:
            frames = read_frames(csv, robot.joint_names)
            commands = read_commands(txt, robot.base_placement)
            peaks.append(tracemalloc.get_traced_memory()[1])
        finally:
            tracemalloc.stop()
        assert frames.rows == rows and len(commands.marks) == 1 + 3  # the clear, three marks
        assert commands.end_s == pytest.approx((rows - 1) / hz, abs=1e-6)
    assert sizes[1] > 1.9 * sizes[0]
    assert peaks[1] < 1.2 * peaks[0], f"{peaks[0] / 1e6:.1f} MB, then {peaks[1] / 1e6:.1f} MB"


def test_a_very_long_recording_is_thinned_to_the_frame_cap(tmp_path: Path) -> None:
    robot = load_robot()
    csv = tmp_path / "take.csv"
    hours = 3 * 3600.0
    with open(csv, "w") as file:  # a row every 0.05 s for three hours
        file.write(header(robot))
        zeros = ",".join(["0"] * (robot.n + 6))
        file.writelines(f"{k * 0.05:.6f},{zeros}\n" for k in range(int(hours / 0.05)))
    frames = read_frames(csv, robot.joint_names)
    assert len(frames.times) <= MAX_HTML_FRAMES + 1


# NAME.txt, streamed


def test_markers_and_objects_are_timed_by_the_sleeps(tmp_path: Path) -> None:
    txt = tmp_path / "take.txt"
    txt.write_text(
        "# robot: motoman_sia20d\nradians\nmotion off\nclear\njoints 0,0,0,0,0,0,0\n"
        "sleep 1.5\nmark 1,2,3,0,0,0\ncolor 0,1,0\nmarker cube\nsleep 0.5\nmark world 1,0,0,0,0,0\n"
        "object crate box 0.1,0.2,0.3 0.5,0.5,0.2,0,0,0\nsleep 1\nclear\n"
        "object crate remove\nsleep 1\ndegrees\nobject ball sphere 0.1 0,0,1\n"
        "object crate box 0.1,0.2,0.3 0.5,0.5,0.2,0,0,0\njoints 1,2,3,4,5,6,7\n"
    )
    base = pin.SE3(np.eye(3), np.array([0.0, 0.0, 0.5]))
    commands = read_commands(txt, base)
    assert not commands.problems and commands.robot == "motoman_sia20d"
    marks = commands.marks
    assert marks[:, 0].tolist() == [0.0, 1.5, 2.0, 3.0]
    assert marks[:, 1].tolist() == [1, 0, 0, 1]  # clear, mark, mark, clear
    assert marks[1, 2:5].tolist() == [1, 2, 3.5]  # in the base frame, shown in the world
    assert marks[2, 2:5].tolist() == [1, 0, 0]  # already in the world frame
    assert marks[2, 9:13].tolist() == [0, 1, 0, 1]  # green, a cube
    names = [o.name for o in commands.objects]
    assert names == ["crate", "ball"] and commands.object_changes == [
        (2.0, (0,)),
        (3.0, ()),
        (4.0, (1,)),
        (4.0, (1, 0)),  # the same crate again: the same object
    ]
    assert commands.end_s == 4.0 and commands.last_joints == (1, 2, 3, 4, 5, 6, 7)


def test_a_flood_of_marks_is_capped_and_said(tmp_path: Path) -> None:
    txt = tmp_path / "take.txt"
    with open(txt, "w") as file:
        file.write("radians\n")
        file.writelines("mark 0,0,1,0,0,0\n" for _ in range(MAX_HTML_MARKS + 5))
    commands = read_commands(txt, pin.SE3.Identity())
    assert len(commands.marks) == MAX_HTML_MARKS
    assert commands.problems == [
        f"take.txt has 5 more marker changes than the page holds ({MAX_HTML_MARKS}); "
        "they are left out"
    ]


# the page


def test_the_page_holds_the_thinned_frames_and_the_robots_kinematics(tmp_path: Path) -> None:
    robot = load_robot()
    csv, txt = write_recording(tmp_path, robot, 300, marks=2)
    path = write_html(recorded(csv, txt, robot), RobotState("arm", robot))
    meta = page_meta(path)
    assert meta["problems"] == [] and meta["robot"] == robot.name and meta["rows"] == 300
    assert [j["name"] for j in meta["joints"]] == list(robot.joint_names)
    times = page_array(path, "times", "<f8")
    values = page_array(path, "values", "<f4").reshape(len(times), robot.n + 6)
    assert len(times) == meta["frames"] and times[-1] == pytest.approx(2.99)
    assert values[-1, :7] == pytest.approx([0.5 * math.sin(2.99 + j) for j in range(7)], abs=1e-6)
    assert meta["markerNodes"] == {"sphere": "/markers/robot/sphere"}
    assert len(meta["linkNodes"]) == len(robot.link_names())
    assert "</script" not in json.dumps(meta).lower()


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ("cut", "take.csv holds 150 frames but take.txt counts 300: the frames were cut short"),
        ("robot", "take.txt is a recording of fanuc_lrmate200id, not of motoman_sia20d"),
        ("other-run", "take.csv's last frame is not take.txt's last joints"),
        ("longer", "take.csv goes on to 2.990 s, past the end of take.txt (1.000 s)"),
        ("no-txt", "take.txt is missing (write error: No space left on device): no markers"),
    ],
)
def test_files_that_disagree_open_with_a_message(tmp_path: Path, change: str, message: str):
    robot = load_robot()
    csv, txt = write_recording(tmp_path, robot, 300)
    text = txt.read_text()
    if change == "cut":
        lines = csv.read_text().splitlines(keepends=True)
        csv.write_text("".join(lines[:151]))
    elif change == "robot":
        txt.write_text(text.replace("# robot: motoman_sia20d", "# robot: fanuc_lrmate200id"))
    elif change == "other-run":
        txt.write_text(re.sub(r"# recorded: .*\n", "", text).replace("joints 0.", "joints 9.")[::1])
    elif change == "longer":
        txt.write_text("radians\nsleep 1\njoints 0,0,0,0,0,0,0\n")
    record = recorded(csv, None if change == "no-txt" else txt, robot)
    if change == "no-txt":
        record = dataclasses.replace(record, error="write error: No space left on device")
    meta = page_meta(write_html(record, RobotState("arm", robot)))
    assert any(message in problem for problem in meta["problems"]), meta["problems"]


def test_a_link_at_name_html_is_replaced_never_followed(tmp_path: Path) -> None:
    robot = load_robot()
    folder = tmp_path / "rec"
    folder.mkdir()
    csv, txt = write_recording(folder, robot, 30)
    outside = tmp_path / "outside.html"
    outside.write_text("keep me")
    (folder / "take.html").symlink_to(outside)
    path = write_html(recorded(csv, txt, robot), RobotState("arm", robot))
    assert outside.read_text() == "keep me"
    assert not path.is_symlink() and page_meta(path)["problems"] == []
    assert sorted(p.name for p in folder.iterdir()) == ["take.csv", "take.html", "take.txt"]
