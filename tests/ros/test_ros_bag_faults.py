"""Issue 39, fault 11: bags that made ``c2rviz-play`` write 150 MB, take a doubled joint's
last value, or hang: a long gap is one ``sleep`` line, a joint named twice is refused, and
a FIFO where a bag file should be is refused before it is opened."""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from ros_helpers import write_rosbag2
from support import load_robot

from c2rviz.clients import player
from c2rviz.ros.bag_reader import JointStateBag
from c2rviz.ros.errors import BadSample, NotABag

CHAIN = tuple(load_robot().joint_names)
JOINTS = ",".join(CHAIN)
HOME = [0.0] * len(CHAIN)


@pytest.mark.parametrize("gap_s", [1e6, 1e9], ids=["11-days", "1e18-ns"])
def test_a_long_gap_is_one_sleep_line(tmp_path: Path, capsys, gap_s: float) -> None:
    bag = write_rosbag2(
        tmp_path / "gap", {"/joint_states": [(0.0, CHAIN, HOME), (gap_s, CHAIN, HOME)]}
    )
    out = tmp_path / "gap.txt"
    argv = [str(bag), "--joints", JOINTS, "--to-commands", str(out)]
    assert player.main(argv) == 0
    lines = out.read_text().splitlines()
    assert [line for line in lines if line.startswith("sleep")] == [f"sleep {gap_s:.0f}"]
    assert len(lines) == 6  # a comment, radians, motion off, joints, sleep, joints
    err = capsys.readouterr().err
    assert f"warning: {bag}: a pause of {gap_s:g} s from 0.000000 s" in err


def test_a_short_gap_is_not_warned_about(tmp_path: Path, capsys) -> None:
    bag = write_rosbag2(
        tmp_path / "gap", {"/joint_states": [(0.0, CHAIN, HOME), (3600.0, CHAIN, HOME)]}
    )
    argv = [str(bag), "--joints", JOINTS, "--to-commands", str(tmp_path / "gap.txt")]
    assert player.main(argv) == 0
    assert capsys.readouterr().err == ""
    assert "\nsleep 3600\n" in (tmp_path / "gap.txt").read_text()


def test_a_joint_named_twice_is_refused(tmp_path: Path, capsys) -> None:
    names = (*CHAIN, CHAIN[1])
    bag = write_rosbag2(tmp_path / "twice", {"/joint_states": [(0.0, names, [*HOME, 0.5])]})
    with JointStateBag.open(bag) as opened, pytest.raises(BadSample, match="twice"):
        list(opened.samples(CHAIN))
    assert player.main([str(bag), "--joints", JOINTS, "--check"]) == 1
    err = capsys.readouterr().err
    assert err == (
        f"c2rviz-play: {bag}: the JointState at 0.000000 s names joint {CHAIN[1]!r} twice; "
        "nothing was sent\n"
    )


def test_a_fifo_is_refused_not_read_forever(tmp_path: Path, capsys) -> None:
    folder = write_rosbag2(tmp_path / "fifo", {"/joint_states": [(0.0, CHAIN, HOME)]})
    (mcap,) = folder.glob("*.mcap")
    mcap.unlink()
    os.mkfifo(mcap)
    bare = tmp_path / "bare.mcap"
    os.mkfifo(bare)
    for path, named in ((folder, mcap), (bare, bare)):
        with pytest.raises(NotABag, match="not a regular file"):
            JointStateBag.open(path)
        assert player.main([str(path), "--joints", JOINTS, "--check"]) == 1
        err = capsys.readouterr().err
        assert err.startswith(f"c2rviz-play: {named}: is not a regular file"), err
