"""Faults in a recording: each fault's line after the frames it caused (a protective
stop's after its braking), and the command file replays without an error."""

from __future__ import annotations

from pathlib import Path

import pytest
from support import Client

from c2rviz.clients import player
from c2rviz.testing.server import TestServer
from c2rviz.world.faults import replay_line

FAR = "1,0.5,0.3,-0.5,0.2,0.5,0.1"


@pytest.mark.parametrize(
    ("event", "line"),
    [
        ("fault estop", "fault estop"),
        ("fault stall joint_l", "fault stall joint_l"),
        ("fault noise 0.01", "fault noise 0.01"),
        ("cleared stall joint_l", "fault clear stall"),
        ("cleared estop", "fault clear estop"),
        ("reset", "reset"),
        ("fault latency 50,10", None),
        ("cleared latency 50,10", None),
        ("fault disconnect", None),
    ],
)
def test_replay_lines(event, line):
    assert replay_line(event) == line


SCRIPT = [
    "record take",
    "motion on",
    "fault after 0.5 protective",
    "joints " + FAR,
    "reset",
    "fault stall joint_e",
    "joints 0.2,0.2,0.3,0,0,0,0",
    "fault clear stall",
    "fault latency 20",
    "fault after 0.3 estop",
    "joints 0,0,0,0,0,0,0",
    "fault clear",
    "reset",
    "joints 0.1,0,0,0,0,0,0",
    "record stop",
]


def test_a_recording_keeps_the_faults_and_replays(tmp_path: Path, capsys):
    server = TestServer({"clock": "virtual", "record": False, "record_dir": tmp_path}).start()
    try:
        client = Client(server.host, server.port)
        replies = [client.ask(line) for line in SCRIPT]
        client.close()
    finally:
        server.stop()
    assert replies[3].startswith("error: protective stop since")
    assert replies[6].startswith("error: joint_e stalled at ")
    assert replies[10].startswith("error: emergency stop since")
    lines = (tmp_path / "take.txt").read_text().splitlines()
    faults = [line for line in lines if line.startswith(("fault", "reset"))]
    assert faults == [
        "fault protective",
        "fault clear protective",
        "reset",
        "fault stall joint_e",
        "fault clear stall",
        "fault estop",
        "fault clear estop",
        "reset",
    ]
    protective = lines.index("fault protective")
    assert lines[protective - 1].startswith("joints ")  # the arm at rest after braking
    assert not any(line.startswith("joints") for line in lines[protective : protective + 3])

    again = TestServer({"clock": "virtual", "record": False}).start()
    try:
        status = player.main([str(tmp_path / "take.txt"), "--port", str(again.port)])
        out = capsys.readouterr().out
        assert status == 0, out
        assert again.run("where") == "ok 0.1,0,0,0,0,0,0"
        assert again.run("faults") == "ok none"
    finally:
        again.stop()


JITTERED = [
    "record take",
    "motion on",
    "fault latency 20,30",
    "fault noise 0.01",
    "joints " + FAR,
    "where",
    "fault after 0.4 stall 1",
    "joints 0,0,0,0,0,0,0",
    "rand",
    "record stop",
]


def recorded(folder: Path, seed: int) -> tuple[list[str], bytes, list[str]]:
    """The replies, NAME.csv's bytes and NAME.txt's lines (its comments aside) of a run."""
    options = {"clock": "virtual", "record": False, "record_dir": folder, "plan_seed": seed}
    server = TestServer(options).start()
    try:
        client = Client(server.host, server.port)
        replies = [client.ask(line) for line in JITTERED]
        client.close()
    finally:
        server.stop()
    body = [line for line in (folder / "take.txt").read_text().splitlines() if line[:1] != "#"]
    return replies[1:-1], (folder / "take.csv").read_bytes(), body  # (not the folders)


def test_the_same_seed_records_the_same_run_byte_for_byte(tmp_path: Path):
    first = recorded(tmp_path / "a", 5)
    assert first == recorded(tmp_path / "b", 5)
    assert first[1] != recorded(tmp_path / "c", 6)[1]  # other jitter: other times
