"""Issue 38's rough edges in recordings: the faults on when ``record`` starts are written at
its start, and a slip's draws are written as their outcomes, so a replay shows the same
faults and makes the same grasps (whatever its own seed draws)."""

from __future__ import annotations

from pathlib import Path

import pytest
from support import Client

from c2rviz.clients import player
from c2rviz.testing.server import TestServer

PICK = "0,0.3,-0.3,0,-0.9707963,0"  # the fanuc's fingers around p1 (test_part_verbs)
SETUP = [
    "grip 1",
    "object table box 0.4,0.6,0.05 0.45,0,0.154,0,0,0",
    "part p1 box 0.03,0.03,0.17 0.4438,0,0.264,0,0,0",
    f"joints {PICK}",
]
GRASPS = 12


def kinds(listing: str) -> list[str]:
    """The faults a ``faults`` reply lists, without their times."""
    assert listing.startswith("ok "), listing
    return [entry.rsplit(" since ", 1)[0] for entry in listing[3:].split("; ")]


def body(txt: Path) -> list[str]:
    return [line for line in txt.read_text().splitlines() if line[:1] != "#"]


def test_faults_on_before_the_recording_are_written_at_its_start(tmp_path: Path) -> None:
    server = TestServer({"clock": "virtual", "record": False, "record_dir": tmp_path}).start()
    try:
        client = Client(server.host, server.port)
        for line in [
            "joints 0.1,0.2,0,0,0,0,0",
            "fault stall joint_e",
            "fault noise 0.01",
            "fault latency 5",  # not written: it would slow the replaying client
            "fault estop",
            "fault clear estop",  # released, but not yet reset
            "camera top 1,0,1.5,0,90,0",
            "fault blackout top 5",
            "fault after 30 protective",  # written when it begins, not ahead
            "sleep 1",
            "record take",
            "sleep 1",
            "record stop",
        ]:
            assert client.ask(line).startswith("ok"), line
        before = kinds(client.ask("faults"))
        client.close()
    finally:
        server.stop()
    assert before[:4] == [
        "stall joint_e",
        "noise 0.01",
        "latency 5,0",
        "estop released, reset needed",
    ]
    assert before[4].startswith("protective at ")
    lines = body(tmp_path / "take.txt")
    first = next(i for i, line in enumerate(lines) if line.startswith("joints "))
    assert lines[first + 1 : first + 5] == [
        "fault stall joint_e",
        "fault noise 0.01",
        "fault estop",
        "fault clear estop",
    ]
    dark = lines[first + 5].split()
    assert dark[:3] == ["fault", "blackout", "top"]  # for the time it has left:
    assert float(dark[3]) == pytest.approx(5 - 1 - 3 * 0.005)  # the sleep, 3 late replies
    again = TestServer({"clock": "virtual", "record": False}).start()
    try:
        assert player.main([str(tmp_path / "take.txt"), "--port", str(again.port)]) == 0
        assert kinds(again.run("faults")) == [
            "stall joint_e",
            "noise 0.01",
            "estop released, reset needed",
        ]
        assert again.run("camera top") == "ok none"  # still dark: ~4 s from the replay's start
        assert again.run("target") == "ok 0.1,0.2,0,0,0,0,0"
        assert again.run("joints 0,0,0,0,0,0,0").startswith("error: emergency stop since")
    finally:
        again.stop()


def grasp_run(folder: Path, seed: int) -> list[str]:
    """``GRASPS`` grasps of p1 under ``fault slip 0.5``, recorded: each ``grip 0``'s reply."""
    options = {"clock": "virtual", "record": False, "record_dir": folder, "plan_seed": seed}
    server = TestServer({"robot": "fanuc_lrmate200id", **options}).start()
    try:
        client = Client(server.host, server.port)
        for line in [*SETUP, "record take", "fault slip 0.5"]:
            assert client.ask(line).startswith("ok"), line
        outcomes = []
        for _ in range(GRASPS):
            outcomes.append(client.ask("grip 0"))
            assert client.ask("grip 1") == "ok"
            assert client.ask("sleep 0.1") == "ok"
        assert client.ask("record stop").startswith("ok")
        client.close()
        return outcomes
    finally:
        server.stop()


def replayed(txt: Path, seed: int) -> list[str]:
    """The replies to the closing ``grip`` lines of ``txt`` played on a server of ``seed``."""
    options = {"robot": "fanuc_lrmate200id", "clock": "virtual", "plan_seed": seed}
    server = TestServer(options).start()
    try:
        client = Client(server.host, server.port)
        out = []
        for line in body(txt):
            reply = client.ask(line)
            assert reply.startswith("ok"), (line, reply)
            if line.startswith("grip ") and float(line.split()[1]) < 1.0:
                out.append(reply)
        client.close()
        return out
    finally:
        server.stop()


def test_a_replay_makes_the_grasps_the_run_made_whatever_its_seed(tmp_path: Path) -> None:
    outcomes = grasp_run(tmp_path, seed=3)
    assert "ok" in outcomes and any(o.startswith("ok 0.") for o in outcomes), outcomes
    lines = body(tmp_path / "take.txt")
    assert "fault slip 0.5" not in lines  # its draws are written instead, as outcomes
    assert {"fault slip 1", "fault slip 0"} <= set(lines)
    for seed in (3, 4, 5):  # the run's own seed, and others that would draw otherwise
        assert replayed(tmp_path / "take.txt", seed) == outcomes
    again = TestServer({"robot": "fanuc_lrmate200id", "clock": "virtual"}).start()
    try:  # and c2rviz-play plays it
        assert player.main([str(tmp_path / "take.txt"), "--port", str(again.port)]) == 0
    finally:
        again.stop()
