"""A write error (a full disk, a file-size limit) stops a bag and leaves it readable.

Two real kernel errors, no stand-in file object: a full tmpfs (ENOSPC; needs the
right to mount, so it is skipped elsewhere) and RLIMIT_FSIZE in a child process
(EFBIG; runs anywhere on Linux). And ``end_mcap`` on a real bag cut anywhere.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
from mcap.reader import make_reader
from ros_helpers import HUMBLE, ROOT, bundled
from rosbags.highlevel import AnyReader

from c2rviz.ros import messages as m
from c2rviz.ros.bag_repair import end_bag, end_mcap
from c2rviz.ros.bag_writer import BagRobot, BagWriter


def read_stamps(path: Path) -> list[tuple[str, int]]:
    """(topic, log time) of every message, through rosbags (which checks the file's end)."""
    with AnyReader([path]) as reader:
        return [(conn.topic, ns) for conn, ns, _ in reader.messages()]


def mcap_count(path: Path) -> int:
    with open(path, "rb") as file:
        return sum(1 for _ in make_reader(file).iter_messages())


def record_until_stopped(
    path: Path, frames: int, **options: object
) -> tuple[BagWriter, list[str], int]:
    """The motoman recorded at 100 Hz until the writer stops (or ``frames`` frames)."""
    robot = bundled("motoman_sia20d")
    reports: list[str] = []
    writer = BagWriter(path, on_error=reports.append, **options)  # type: ignore[arg-type]
    arm = BagRobot(writer, robot)
    arm.start(0.0)
    rng = np.random.default_rng(2)
    written = 0
    while written < frames and writer.error is None:
        arm.frame(written * 0.01, robot.random(rng))
        written += 1
    return writer, reports, written


def check_ended(path: Path, written: int) -> None:
    """A readable bag, holding a prefix of what was written, in time order."""
    assert not (path / ".c2rviz-reserve").exists()
    stamps = read_stamps(path)  # through metadata.yaml and the .mcap
    assert read_stamps(path / f"{path.name}.mcap") == stamps  # the file alone too
    joint_states = [ns for topic, ns in stamps if topic == "/joint_states"]
    assert 0 < len(joint_states) < written
    assert joint_states == [m.nanoseconds(i * 0.01) for i in range(len(joint_states))]
    assert mcap_count(path / f"{path.name}.mcap") == len(stamps)
    with AnyReader([path]) as reader:
        assert reader.message_count == len(stamps)


@pytest.fixture
def full_disk(tmp_path: Path) -> Iterator[Path]:
    """A 4 MiB tmpfs, if this process may mount one."""
    mount = tmp_path / "tmpfs"
    mount.mkdir()
    done = subprocess.run(
        ["mount", "-t", "tmpfs", "-o", "size=4m", "tmpfs", str(mount)],
        capture_output=True,
        check=False,
    )
    if done.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here: {done.stderr.decode().strip()}")
    try:
        yield mount
    finally:
        subprocess.run(["umount", str(mount)], check=True)


def test_a_full_disk_stops_the_bag_readable(full_disk: Path) -> None:
    writer, reports, written = record_until_stopped(full_disk / "rec", 100_000)
    assert reports == ["write error: No space left on device"]  # once
    assert writer.closed and writer.error == reports[0]
    writer.close()  # harmless
    writer.text("/c2rviz/replies", 99.0, "ok")  # ignored
    assert reports == [reports[0]]
    check_ended(full_disk / "rec", written)


CHILD = """
import json, resource, signal, sys
from pathlib import Path
sys.path.insert(0, {tests!r})
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a write past the limit fails with EFBIG
resource.setrlimit(resource.RLIMIT_FSIZE, (3_000_000, resource.RLIM_INFINITY))
from test_ros_write_errors import record_until_stopped
writer, reports, written = record_until_stopped(Path({path!r}), 100_000)
writer.close()
print(json.dumps({{"reports": reports, "written": written}}))
"""


def test_a_file_size_limit_stops_the_bag_readable(tmp_path: Path) -> None:
    path = tmp_path / "rec"
    code = CHILD.format(tests=str(Path(__file__).parent), path=str(path))
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    done = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        env=env,
        check=True,
        timeout=100,
    )
    result = json.loads(done.stdout.strip().splitlines()[-1])
    assert result["reports"] == ["write error: File too large"]
    assert "stopped by a write error: File too large; it is ended" in done.stderr
    check_ended(path, result["written"])


@pytest.fixture(scope="module")
def whole_bag(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, list[tuple[str, int]]]:
    """A closed bag of several chunks (rosbags closes a chunk past 1 MiB)."""
    path = tmp_path_factory.mktemp("whole") / "rec"
    writer, reports, _ = record_until_stopped(path, 3000)
    writer.close()
    assert reports == []
    return path, read_stamps(path)


@pytest.mark.parametrize("fraction", [0.0, 0.001, 0.2, 0.35, 0.5, 0.71, 0.9, 0.999, 0.99999])
def test_a_bag_cut_anywhere_ends_readable(
    tmp_path: Path, whole_bag: tuple[Path, list[tuple[str, int]]], fraction: float
) -> None:
    """Cut the .mcap anywhere (even in its summary): what stays is a prefix of the messages."""
    source, everything = whole_bag
    data = (source / "rec.mcap").read_bytes()
    cut = tmp_path / "rec"
    cut.mkdir()
    (cut / "rec.mcap").write_bytes(data[: int(len(data) * fraction)])
    assert end_mcap(cut / "rec.mcap")
    assert not end_mcap(cut / "rec.mcap")  # ended once: left alone
    count = end_bag(cut, HUMBLE)  # a folder with no metadata.yaml yet
    stamps = read_stamps(cut)
    assert stamps == everything[: len(stamps)] and count == len(stamps)
    assert mcap_count(cut / "rec.mcap") == len(stamps)
    if fraction >= 0.999:
        assert len(stamps) == len(everything)  # only the summary was cut


def test_a_whole_bag_is_left_alone(whole_bag: tuple[Path, list[tuple[str, int]]]) -> None:
    source, _ = whole_bag
    before = (source / "rec.mcap").read_bytes()
    assert not end_mcap(source / "rec.mcap")
    assert (source / "rec.mcap").read_bytes() == before


def test_a_killed_recording_is_ended_afterwards(tmp_path: Path) -> None:
    """A process killed mid-recording leaves an .mcap without its end; end_bag ends it."""
    path = tmp_path / "rec"
    code = (
        "import os, sys\n"
        f"sys.path.insert(0, {str(Path(__file__).parent)!r})\n"
        "from pathlib import Path\n"
        "from test_ros_write_errors import record_until_stopped\n"
        f"writer, _, _ = record_until_stopped(Path({str(path)!r}), 3000)\n"
        "os._exit(0)  # no close: as a SIGKILL would leave it\n"
    )
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    subprocess.run([sys.executable, "-c", code], env=env, check=True, timeout=100)
    assert not (path / "metadata.yaml").exists()
    with pytest.raises(Exception, match="end magic"):
        read_stamps(path / "rec.mcap")
    count = end_bag(path, HUMBLE)
    stamps = read_stamps(path)
    assert 0 < count == len(stamps) and stamps == sorted(stamps, key=lambda s: s[1])
