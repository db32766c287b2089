"""A recording with a ``fault drop`` replays to the same final part poses: NAME.txt keeps
the fault's line at its time, among the frames of the carry it cut short."""

from __future__ import annotations

from pathlib import Path

from support import Client, ServerLimits, ServerThread, load_robot

from c2rviz.clients import player
from c2rviz.world.virtual_clock import VirtualClock

PICK = "0,0.3,-0.3,0,-0.9707963,0"  # the fanuc pointing down at the part (test_part_verbs)
LIFT = "0,0,0,0,-1.5707963,0"
AWAY = "1.2,0,0,0,-1.5707963,0"
SETUP = [
    "grip 1",
    "object table box 0.4,0.6,0.05 0.45,0,0.154,0,0,0",
    "part p1 box 0.03,0.03,0.17 0.4438,0,0.264,0,0,0",
]
RUN = [
    "motion on",
    f"joints {PICK}",
    "grip 0",
    f"joints {LIFT}",
    "fault after 0.4 drop p1",  # 0.4 s into the carry
    f"joints {AWAY}",
    "sleep 1",
]


def _server(tmp_path: Path) -> ServerThread:
    robot = load_robot("fanuc_lrmate200id")
    return ServerThread(robot, ServerLimits(), clock=VirtualClock(), record_dir=tmp_path).start()


def test_a_recorded_drop_replays_to_the_same_part_poses(tmp_path: Path) -> None:
    first = _server(tmp_path)
    client = Client(first.host, first.port)
    try:
        for line in SETUP:
            assert client.ask(line).startswith("ok"), line
        assert client.ask("record take").startswith("ok recording take")
        for line in RUN:
            assert client.ask(line).startswith("ok"), line
        final = client.ask("parts")
        assert final.startswith("ok p1:") and final.endswith(":resting on table"), final
        assert client.ask("record stop").startswith("ok")
    finally:
        client.close()
        first.stop()
    lines = (tmp_path / "take.txt").read_text().splitlines()
    drop = lines.index("fault drop p1")
    assert any(line.startswith("joints 1.2,") for line in lines[drop:])  # mid-carry
    assert any(line.startswith("joints 0.") for line in lines[drop - 3 : drop])
    (tmp_path / "replay").mkdir()
    second = _server(tmp_path / "replay")
    try:
        assert player.main([str(tmp_path / "take.txt"), "--port", str(second.port)]) == 0
        replayed = Client(second.host, second.port)
        try:
            assert replayed.ask("sleep 1") == "ok"
            assert replayed.ask("parts") == final
        finally:
            replayed.close()
    finally:
        second.stop()
