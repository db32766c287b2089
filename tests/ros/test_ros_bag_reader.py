"""JointStateBag reads bags written by rosbags itself (rosbag2 MCAP and SQLite, ROS 1), and refuses
each kind of bad bag with one line."""

from __future__ import annotations

import math
import shutil
from collections.abc import Sequence
from pathlib import Path

import pytest
from ros_helpers import HUMBLE, humble_joint_state, sweep, write_rosbag1, write_rosbag2
from rosbags.rosbag2 import StoragePlugin, Writer

from c2rviz.ros.bag_reader import JointStateBag
from c2rviz.ros.errors import (
    AmbiguousTopic,
    BadSample,
    BagCorrupted,
    EmptySpan,
    MissingJoint,
    NoJointStateTopic,
    NotABag,
    StampsBackwards,
    UnknownTopic,
)

CHAIN = ("joint_1", "joint_2", "joint_3")
SAMPLES = sweep(CHAIN, 500)  # 5 s at 100 Hz


def chain_values(t: float) -> tuple[float, ...]:
    return tuple(0.1 * k + math.sin(t) for k in range(len(CHAIN)))


@pytest.fixture(scope="module")
def mcap_bag(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_rosbag2(tmp_path_factory.mktemp("bags") / "arm", {"/joint_states": SAMPLES})


@pytest.mark.parametrize("kind", ["folder", "bare-mcap", "sqlite", "ros1"])
def test_every_kind_of_bag_plays_the_same(tmp_path: Path, mcap_bag: Path, kind: str) -> None:
    path = {
        "folder": lambda: mcap_bag,
        "bare-mcap": lambda: mcap_bag / "arm.mcap",
        "sqlite": lambda: write_rosbag2(
            tmp_path / "db", {"/joint_states": SAMPLES}, storage=StoragePlugin.SQLITE3
        ),
        "ros1": lambda: write_rosbag1(tmp_path / "arm.bag", "/joint_states", SAMPLES),
    }[kind]()
    with JointStateBag.open(path) as bag:
        assert (bag.topic, bag.count) == ("/joint_states", 500)
        assert bag.duration_s == pytest.approx(4.99)
        assert bag.check(CHAIN) == []
        played = list(bag.samples(CHAIN))
    assert [t for t, _ in played] == pytest.approx([t for t, _, _ in SAMPLES], abs=1e-9)
    assert all(q == chain_values(t) for (t, q), (t, _, _) in zip(played, SAMPLES))


def test_a_span_is_exactly_start_to_start_plus_duration(mcap_bag: Path) -> None:
    with JointStateBag.open(mcap_bag) as bag:
        times = [t for t, _ in bag.samples(CHAIN, start_s=1.0, duration_s=0.5)]
        to_end = [t for t, _ in bag.samples(CHAIN, start_s=4.9)]
    assert times == pytest.approx([1.0 + i / 100 for i in range(50)])
    assert to_end == pytest.approx([4.9, 4.91, 4.92, 4.93, 4.94, 4.95, 4.96, 4.97, 4.98, 4.99])


def test_chain_order_extra_joints_and_other_groups(tmp_path: Path) -> None:
    """Names in any order; joints off the chain warned once; a gripper's messages skipped."""
    arm: list[Sample] = [
        (i / 100, ("gripper", "joint_3", "joint_1", "joint_2"), (9.0, 3.0, 1.0, 2.0))
        for i in range(10)
    ]
    gripper: list[Sample] = [(i / 100 + 0.005, ("gripper",), (0.5,)) for i in range(10)]
    path = write_rosbag2(
        tmp_path / "mixed", {"/joint_states": sorted(arm + gripper, key=lambda s: s[0])}
    )
    with JointStateBag.open(path) as bag:
        warnings = bag.check(CHAIN)
        played = list(bag.samples(CHAIN))
    assert warnings == [
        "/joint_states also names joints the chain does not have, ignored: gripper",
        "10 JointState messages on /joint_states name none of the chain's joints and were skipped",
    ]
    assert [q for _, q in played] == [(1.0, 2.0, 3.0)] * 10


def test_choosing_among_topics(tmp_path: Path) -> None:
    path = write_rosbag2(
        tmp_path / "cell",
        {"/left/joint_states": SAMPLES[:10], "/right/joint_states": SAMPLES[:20]},
    )
    with pytest.raises(AmbiguousTopic) as error:
        JointStateBag.open(path)
    assert str(error.value) == (
        f"{path}: has 2 JointState topics, choose one with --topic: "
        "/left/joint_states, /right/joint_states"
    )
    for topic in ("/right/joint_states", "right/joint_states"):
        with JointStateBag.open(path, topic) as bag:
            assert (bag.topic, bag.count) == ("/right/joint_states", 20)
    with pytest.raises(
        UnknownTopic,
        match="no JointState topic '/middle/joint_states'; its JointState topics: /left",
    ):
        JointStateBag.open(path, "/middle/joint_states")


def test_no_joint_state_topic_lists_what_there_is(tmp_path: Path) -> None:
    text = HUMBLE.types["std_msgs/msg/String"](data="hello")
    path = write_rosbag2(tmp_path / "chat", {}, [("/chatter", "std_msgs/msg/String", 0.0, text)])
    with pytest.raises(NoJointStateTopic) as error:
        JointStateBag.open(path)
    assert (
        str(error.value) == f"{path}: has no sensor_msgs/JointState topic; "
        "its topics: /chatter (std_msgs/msg/String)"
    )


def _damaged(tmp_path: Path, mcap_bag: Path, kind: str) -> Path:
    if kind == "missing":
        return tmp_path / "nothing-here"
    if kind == "text":
        (tmp_path / "notes.txt").write_text("joints 1 2 3\n")
        return tmp_path / "notes.txt"
    if kind == "text-as-mcap":
        (tmp_path / "notes.mcap").write_text("joints 1 2 3\n" * 10)
        return tmp_path / "notes.mcap"
    if kind == "empty-mcap":
        (tmp_path / "empty.mcap").write_bytes(b"")
        return tmp_path / "empty.mcap"
    if kind == "folder":
        (tmp_path / "folder").mkdir()
        return tmp_path / "folder"
    if kind == "text-as-db3":
        (tmp_path / "notes.db3").write_text("joints 1 2 3\n" * 10)
        return tmp_path / "notes.db3"
    if kind == "bad-metadata":
        shutil.copytree(mcap_bag, tmp_path / "arm")
        (tmp_path / "arm" / "metadata.yaml").write_text("rosbag2_bagfile_information: [\n  {a: b\n")
        return tmp_path / "arm"
    if kind == "text-as-bag":
        (tmp_path / "notes.bag").write_text("#ROSBAG V2.0\n" + "x" * 100)
        return tmp_path / "notes.bag"
    data = (mcap_bag / "arm.mcap").read_bytes()
    if kind == "truncated-mcap":
        (tmp_path / "cut.mcap").write_bytes(data[: len(data) // 2])
        return tmp_path / "cut.mcap"
    if kind == "truncated-folder":
        shutil.copytree(mcap_bag, tmp_path / "arm")
        (tmp_path / "arm" / "arm.mcap").write_bytes(data[: len(data) * 2 // 3])
        return tmp_path / "arm"
    assert kind == "truncated-ros1"
    full = write_rosbag1(tmp_path / "full.bag", "/joint_states", SAMPLES).read_bytes()
    (tmp_path / "cut.bag").write_bytes(full[: len(full) // 2])
    return tmp_path / "cut.bag"


@pytest.mark.parametrize(
    ("kind", "error", "words"),
    [
        ("missing", NotABag, "does not exist; give a rosbag2 folder"),
        ("text", NotABag, "is not a bag (by its name)"),
        ("text-as-mcap", NotABag, "is not a bag (File magic is invalid)"),
        ("empty-mcap", NotABag, "seems to be empty"),
        ("folder", NotABag, "is a folder without metadata.yaml"),
        ("text-as-db3", NotABag, "file is not a database"),
        ("bad-metadata", BagCorrupted, "Could not load YAML"),
        ("text-as-bag", BagCorrupted, "is truncated or damaged"),
        ("truncated-mcap", BagCorrupted, "is truncated or damaged"),
        ("truncated-folder", BagCorrupted, "is truncated or damaged"),
        ("truncated-ros1", BagCorrupted, "is truncated or damaged"),
    ],
    ids=lambda x: x if isinstance(x, str) and " " not in x else None,
)
def test_what_is_not_a_whole_bag(
    tmp_path: Path, mcap_bag: Path, kind: str, error: type, words: str
) -> None:
    path = _damaged(tmp_path, mcap_bag, kind)
    with pytest.raises(error) as caught:
        JointStateBag.open(path)
    message = str(caught.value)
    assert message.startswith(f"{path}: ") and words in message
    assert "\n" not in message


Sample = tuple[float, Sequence[str], Sequence[float]]


def _bad(
    samples: Sequence[Sample], at: int, names: Sequence[str], values: Sequence[float]
) -> list[Sample]:
    out = list(samples)
    out[at] = (out[at][0], names, values)
    return out


GOOD: list[Sample] = [(t, CHAIN, (0.1, 0.2, 0.3)) for t, _, _ in SAMPLES[:300]]


@pytest.mark.parametrize(
    ("samples", "error", "words"),
    [
        (
            _bad(GOOD, 250, CHAIN, (0.1, math.nan, 0.3)),
            BadSample,
            "joint 'joint_2' is nan at 2.500000 s",
        ),
        (
            _bad(GOOD, 251, CHAIN, (0.1, 0.2, -math.inf)),
            BadSample,
            "joint 'joint_3' is -inf at 2.510000 s",
        ),
        (
            _bad(GOOD, 252, ("joint_1", "joint_3"), (0.1, 0.3)),
            MissingJoint,
            "chain joint 'joint_2' is missing from the JointState at 2.520000 s "
            "(it names: joint_1, joint_3)",
        ),
        (
            _bad(GOOD, 253, CHAIN, (0.1, 0.2)),
            BadSample,
            "at 2.530000 s has 3 names and 2 positions",
        ),
        (
            [(t, ("a", "b"), (1.0, 2.0)) for t, _, _ in GOOD],
            MissingJoint,
            "chain joint 'joint_1' is missing from the JointState at 0.000000 s (it names: a, b)",
        ),
    ],
    ids=["nan", "inf", "missing-joint", "lengths", "other-robot"],
)
def test_check_refuses_the_span_at_its_first_problem(
    tmp_path: Path, request: pytest.FixtureRequest, samples: list, error: type, words: str
) -> None:
    path = write_rosbag2(tmp_path / "bad", {"/joint_states": samples})
    with JointStateBag.open(path) as bag:
        with pytest.raises(error) as caught:
            bag.check(CHAIN)
        assert words in str(caught.value) and "\n" not in str(caught.value)
        if "other" not in request.node.callspec.id:  # the span before the problem plays
            assert bag.check(CHAIN, start_s=0.0, duration_s=2.0) == []


def test_stamps_going_backwards(tmp_path: Path) -> None:
    stamps = {GOOD[100][0]: round(0.5 * 1e9)}  # the message at 1.00 s says 0.5 s
    path = write_rosbag2(tmp_path / "jump", {"/joint_states": GOOD}, stamps=stamps)
    with JointStateBag.open(path) as bag:
        with pytest.raises(
            StampsBackwards,
            match="stamps go backwards at 1.000000 s: stamp 0.500000000 s after 0.990000000 s",
        ):
            bag.check(CHAIN)
        assert bag.check(CHAIN, start_s=1.005) == []  # after the jump they climb again


@pytest.mark.parametrize(
    ("start_s", "duration_s", "words"),
    [
        (-1.0, None, "start -1.0 s is not a time in the bag"),
        (math.nan, None, "start nan s"),
        (0.0, 0.0, "duration 0.0 s is not a positive time"),
        (9.0, None, "starts at 9.0 s, after its end (2.990 s)"),
    ],
    ids=["negative", "nan", "zero-duration", "after-end"],
)
def test_spans_outside_the_bag(
    tmp_path: Path, start_s: float, duration_s: float | None, words: str
) -> None:
    path = write_rosbag2(tmp_path / "b", {"/joint_states": GOOD})
    with (
        JointStateBag.open(path) as bag,
        pytest.raises(EmptySpan, match=words.replace("(", r"\(").replace(")", r"\)")),
    ):
        bag.check(CHAIN, start_s, duration_s)


def test_a_span_with_no_message(tmp_path: Path) -> None:
    gap = GOOD[:50] + [(3.0, CHAIN, (0.1, 0.2, 0.3))]
    path = write_rosbag2(tmp_path / "gap", {"/joint_states": gap})
    with JointStateBag.open(path) as bag, pytest.raises(EmptySpan, match="from 1 s to 2 s"):
        bag.check(CHAIN, 1.0, 1.0)


def test_samples_are_lazy(mcap_bag: Path) -> None:
    """The first sample comes before the rest is read: a generator over the bag."""
    with JointStateBag.open(mcap_bag) as bag:
        stream = bag.samples(CHAIN)
        first = next(stream)
        assert first[0] == 0.0
        stream.close()
    assert humble_joint_state(CHAIN, first[1], 0).position.tolist() == list(first[1])


def test_big_endian_cdr_plays_through_rosbags(tmp_path: Path) -> None:
    """The quick decoder reads little-endian CDR; rosbags' deserializer takes the rest."""
    with Writer(tmp_path / "be", version=9, storage_plugin=StoragePlugin.MCAP) as writer:
        conn = writer.add_connection(
            "/joint_states", "sensor_msgs/msg/JointState", typestore=HUMBLE
        )
        for t, names, positions in SAMPLES[:20]:
            state = humble_joint_state(names, positions, round(t * 1e9))
            raw = HUMBLE.serialize_cdr(state, "sensor_msgs/msg/JointState", little_endian=False)
            writer.write(conn, round(t * 1e9), raw)
    with JointStateBag.open(tmp_path / "be") as bag:
        played = list(bag.samples(CHAIN))
    assert [q for _, q in played] == [chain_values(t) for t, _, _ in SAMPLES[:20]]


def test_damage_inside_the_bag_is_met_while_reading(tmp_path: Path, mcap_bag: Path) -> None:
    """A chunk damaged in the middle of an indexed file: the open succeeds, the check does not."""
    shutil.copytree(mcap_bag, tmp_path / "arm")
    data = bytearray((tmp_path / "arm" / "arm.mcap").read_bytes())
    middle = data.find(b"joint_2", len(data) // 2)
    data[middle - 40 : middle + 40] = b"\xff" * 80  # a message's lengths and names overwritten
    (tmp_path / "arm" / "arm.mcap").write_bytes(bytes(data))
    with JointStateBag.open(tmp_path / "arm") as bag, pytest.raises(BagCorrupted) as caught:
        bag.check(CHAIN)
    assert "\n" not in str(caught.value) and "damaged" in str(caught.value)
