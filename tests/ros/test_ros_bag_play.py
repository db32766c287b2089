"""``c2rviz-play BAG`` and the REPL's ``file BAG``: bags written with rosbags itself (rosbag2
MCAP, a bare .mcap, ROS 1) played into a real server, and every bad bag refused whole.

What the server's world showed (its scene's every state) is compared with the bag's
samples in chain order; a bad bag, or a bad value anywhere in the span, gets one line
on stderr, exit status 1, and moves nothing (the server heard only `names` and
`limits`).
"""

from __future__ import annotations

import io
import math
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np
import pytest
from ros_helpers import HUMBLE, sweep, write_rosbag1, write_rosbag2
from support import Client, ServerThread, load_robot

from c2rviz.clients import player
from c2rviz.clients.client import Client as TypedClient
from c2rviz.clients.repl_local import LocalCommands

ROBOT = load_robot()
CHAIN = tuple(ROBOT.joint_names)
N = 300  # 3 s at 100 Hz
RATE = 10.0  # tests play at 10 x the bag's pace


def samples(n: int = N, names: Sequence[str] = CHAIN) -> list:
    """``sweep`` kept well inside the motoman's limits."""
    return [(t, names, [0.3 * v for v in q]) for t, _, q in sweep(names, n)]


def chain_of(sample: tuple) -> list[float]:
    """A sample's values in chain order (its names may be in any order, with extras)."""
    _, names, values = sample
    where = dict(zip(names, values))
    return [where[name] for name in CHAIN]


def shown(server: ServerThread) -> list[tuple[float, ...]]:
    return server.call(lambda: list(server.scene.joints))


def heard(server: ServerThread) -> list[str]:
    return server.call(lambda: list(server.scene.commands))


def play(server: ServerThread, bag: Path, *flags: str) -> int:
    return player.main([str(bag), "--port", str(server.port), "--rate", str(RATE), *flags])


@pytest.fixture
def mcap_bag(tmp_path: Path) -> Path:
    """Names in another order than the chain's, and a gripper joint the chain lacks."""
    names = ("gripper", *reversed(CHAIN))
    moved = [(t, names, [0.02, *reversed(q)]) for t, _, q in samples()]
    return write_rosbag2(tmp_path / "arm", {"/joint_states": moved})


@pytest.mark.parametrize("kind", ["folder", "bare-mcap", "ros1"])
def test_a_bag_plays_into_a_real_server(
    server: ServerThread, tmp_path: Path, mcap_bag: Path, capsys, kind: str
) -> None:
    path = {
        "folder": mcap_bag,
        "bare-mcap": mcap_bag / "arm.mcap",
        "ros1": write_rosbag1(tmp_path / "arm.bag", "/arm/joint_states", samples()),
    }[kind]
    assert play(server, path) == 0
    out, err = capsys.readouterr()
    if kind != "ros1":  # the extra joint is named once
        assert err == (
            f"c2rviz-play: warning: {path}: /joint_states also names joints the chain does not "
            "have, ignored: gripper\n"
        )
    assert out.startswith(f"{path}: ") and ", all ok, in " in out
    want = [chain_of(s) for s in samples()]
    np.testing.assert_allclose(shown(server), want, rtol=0, atol=0)  # every state, exact
    times = server.call(lambda: list(server.scene.times))
    assert times[-1] - times[0] >= (samples()[-1][0] - 0.05) / RATE  # at the bag's pace
    assert heard(server)[:4] == ["names", "limits", "radians", "motion off"]


def test_a_span_loops_and_writes_the_same_command_file(
    server: ServerThread, connect: Callable[..., Client], tmp_path: Path, mcap_bag: Path
) -> None:
    assert play(server, mcap_bag, "--start", "1", "--duration", "0.5", "--loop", "2") == 0
    span = [chain_of(s) for s in samples() if 1.0 - 1e-9 <= s[0] < 1.5 - 1e-9]  # [start, end)
    assert len(span) == 50
    np.testing.assert_allclose(shown(server), span + span, rtol=0, atol=0)
    out = tmp_path / "span.txt"
    assert player.main([str(mcap_bag), "--port", str(server.port), "--start", "1",
                        "--duration", "0.5", "--to-commands", str(out)]) == 0  # fmt: skip
    text = out.read_text()
    assert text.startswith(f"# c2rviz commands from the bag {mcap_bag}: /joint_states, from 1 s")
    assert "# robot: motoman_sia20d\nradians\nmotion off\njoints " in text
    assert text.count("\njoints ") == 50 and text.count("\nsleep 0.01\n") == 49
    before = len(shown(server))
    assert player.main([str(out), "--port", str(server.port), "--speed", str(RATE)]) == 0
    np.testing.assert_allclose(shown(server)[before:], span, rtol=0, atol=0)
    # Without a server: the chain named on the command line.
    offline = tmp_path / "offline.txt"
    joints = ",".join(CHAIN)
    assert player.main([str(mcap_bag), "--joints", joints, "--start", "1", "--duration", "0.5",
                        "--to-commands", str(offline)]) == 0  # fmt: skip
    assert offline.read_text().split("\n", 1)[1] == text.split("\n", 2)[2]  # no robot line


def test_the_repl_plays_a_bag_and_restores_its_connection(
    server: ServerThread, mcap_bag: Path
) -> None:
    client = TypedClient("127.0.0.1", server.port)
    out = io.StringIO()
    local = LocalCommands(client, out=out, info=out, speed=RATE)
    try:
        assert client.ask("degrees") == "ok" and client.ask("motion follow") == "ok"
        assert local.local["file"]([str(mcap_bag)]) is True
        assert local.errors == 0, out.getvalue()
        assert client.ask("motion") == "ok follow" and client.degrees
        np.testing.assert_allclose(shown(server), [chain_of(s) for s in samples()], atol=0)
        nan = write_rosbag2(mcap_bag.parent / "nan", {"/joint_states": nan_at_the_end()})
        assert local.local["file"]([str(nan)]) is True and local.errors == 1
        assert "is nan at 2.990000 s (not a finite number); nothing was sent" in out.getvalue()
    finally:
        client.close()


def nan_at_the_end() -> list:
    bad = samples()
    t, names, q = bad[-1]
    bad[-1] = (t, names, [math.nan, *q[1:]])
    return bad


def _bad(tmp_path: Path, kind: str) -> tuple[Path, list[str]]:
    """A bad bag of ``kind`` and the flags it is played with."""
    good = samples()
    if kind == "missing":
        return tmp_path / "nothing.mcap", []
    if kind == "text":
        (tmp_path / "notes.mcap").write_text("joints 1 2 3\n" * 10)
        return tmp_path / "notes.mcap", []
    if kind == "folder":
        (tmp_path / "folder").mkdir()
        return tmp_path / "folder", []
    if kind in ("truncated", "damaged"):
        bag = write_rosbag2(tmp_path / "arm", {"/joint_states": good})
        data = bytearray((bag / "arm.mcap").read_bytes())
        if kind == "truncated":
            (tmp_path / "cut.mcap").write_bytes(bytes(data[: len(data) // 2]))
            return tmp_path / "cut.mcap", []
        middle = data.find(CHAIN[1].encode(), len(data) // 2)
        data[middle - 40 : middle + 40] = b"\xff" * 80
        (bag / "arm.mcap").write_bytes(bytes(data))
        return bag, []
    if kind == "no-joint-states":
        text = HUMBLE.types["std_msgs/msg/String"](data="hello")
        others = [("/chatter", "std_msgs/msg/String", 0.0, text)]
        return write_rosbag2(tmp_path / "talk", {}, others), []
    if kind in ("two-topics", "wrong-topic"):
        bag = write_rosbag2(tmp_path / "two", {"/a/joint_states": good, "/b/joint_states": good})
        return bag, ["--topic", "/c"] if kind == "wrong-topic" else []
    if kind == "foreign-names":
        return write_rosbag2(tmp_path / "f", {"/js": samples(names=["a", "b"])}), []
    if kind == "missing-joint":
        short = [(t, names[:-1], q[:-1]) for t, names, q in good]
        return write_rosbag2(tmp_path / "short", {"/js": short}), []
    if kind == "nan":
        return write_rosbag2(tmp_path / "nan", {"/js": nan_at_the_end()}), []
    if kind == "inf":
        bad = samples()
        bad[150] = (bad[150][0], CHAIN, [0, 0, math.inf, 0, 0, 0, 0])
        return write_rosbag2(tmp_path / "inf", {"/js": bad}), []
    if kind == "backwards":
        stamps = {good[200][0]: round(good[100][0] * 1e9)}
        return write_rosbag2(tmp_path / "back", {"/js": good}, stamps=stamps), []
    if kind == "beyond-limits":
        bad = samples()
        bad[-1] = (bad[-1][0], CHAIN, [0, 0, 0, 0, 0, 0, 7.0])
        return write_rosbag2(tmp_path / "far", {"/js": bad}), []
    assert kind == "after-the-end"
    return write_rosbag2(tmp_path / "arm", {"/joint_states": good}), ["--start", "10"]


BAD = [
    ("missing", "nothing.mcap: does not exist; give a rosbag2 folder"),
    ("text", "notes.mcap: is not a bag (File magic is invalid)"),
    ("folder", "folder: is a folder without metadata.yaml"),
    ("truncated", "cut.mcap: is truncated or damaged"),
    ("damaged", "damaged"),
    (
        "no-joint-states",
        "has no sensor_msgs/JointState topic; its topics: /chatter (std_msgs/msg/String)",
    ),  # fmt: skip
    (
        "two-topics",
        "has 2 JointState topics, choose one with --topic: /a/joint_states, /b/joint_states",
    ),  # fmt: skip
    ("wrong-topic", "has no JointState topic '/c'; its JointState topics: /a/joint_states"),
    (
        "foreign-names",
        "chain joint 'joint_s' is missing from the JointState at 0.000000 s (it names: a, b)",
    ),  # fmt: skip
    ("missing-joint", "chain joint 'joint_t' is missing from the JointState at 0.000000 s"),
    ("nan", "joint 'joint_s' is nan at 2.990000 s (not a finite number)"),
    ("inf", "joint 'joint_e' is inf at 1.500000 s (not a finite number)"),
    ("backwards", "JointState stamps go backwards at 2.000000 s"),
    ("beyond-limits", "joint 'joint_t' is 7 rad at 2.990000 s, outside its limits"),
    ("after-the-end", "starts at 10.0 s, after its end (2.990 s)"),
]


@pytest.mark.parametrize(("kind", "words"), BAD, ids=[kind for kind, _ in BAD])
def test_a_bad_bag_moves_nothing(
    server: ServerThread, tmp_path: Path, capsys, kind: str, words: str
) -> None:
    path, flags = _bad(tmp_path, kind)
    assert play(server, path, *flags) == 1
    out, err = capsys.readouterr()
    assert out == ""
    assert err.count("\n") == 1 and err.startswith("c2rviz-play: ") and words in err, err
    assert err.endswith("; nothing was sent\n")
    assert shown(server) == []
    assert set(heard(server)) <= {"names", "limits"}


def test_bad_flags(server: ServerThread, mcap_bag: Path, capsys) -> None:
    assert play(server, mcap_bag, "--to-commands", "x.txt", "--loop", "2") == 2
    assert "--to-commands writes the span once" in capsys.readouterr().err
    assert play(server, mcap_bag, "--duration", "-1") == 1
    assert "duration -1.0 s is not a positive time" in capsys.readouterr().err
    assert shown(server) == []


def test_lines_are_sent_as_the_bag_is_read(
    server: ServerThread, mcap_bag: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Streamed, never gathered: when the 100th line is read from the bag, the lines before
    it have been answered already (memory stays flat however long the bag)."""
    from c2rviz.clients import bag_play

    answered_then: list[int] = []
    read = bag_play.command_lines

    def watched(span: bag_play.BagSpan):  # type: ignore[no-untyped-def]
        for k, line in enumerate(read(span)):
            if k == 100:
                answered_then.append(len(heard(server)))
            yield line

    monkeypatch.setattr(bag_play, "command_lines", watched)
    assert play(server, mcap_bag, "--window", "1") == 0
    assert answered_then and answered_then[0] >= 4 + 99  # names, limits, radians, motion off
