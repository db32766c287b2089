"""A disk that fills mid-recording (issue 39, fault 10): every file is whole or absent.

The command file's header counts the frames and time its body kept (not those still in
a buffer when the disk filled), the page NAME.html is written whole or not at all (no
``.part`` left on the full disk) with a warning that says so, and nothing private of the
recording stays behind. Shown on a real small tmpfs when this machine may mount one
(root), and always with the kernel's own ``ENOSPC`` from ``/dev/full`` or a writer that
fills at a byte count.
"""

from __future__ import annotations

import contextlib
import errno
import logging
import os
import shutil
import subprocess
from collections.abc import Iterator
from pathlib import Path
from typing import TextIO

import pytest
from support import Client, ServerThread, load_robot

from c2rviz.app.program import write_page
from c2rviz.observers.recorded import Recorded
from c2rviz.session import ServerLimits
from c2rviz.view import record_page
from c2rviz.world.state import RobotState
from c2rviz.world.virtual_clock import VirtualClock


@pytest.fixture
def virtual_server(tmp_path: Path) -> Iterator[ServerThread]:
    """A motoman server on virtual time recording into ``tmp_path/rec`` (made by the test)."""
    server = ServerThread(
        load_robot("motoman_sia20d"),
        ServerLimits(),
        clock=VirtualClock(),
        record_dir=tmp_path / "rec",
    )
    yield server
    if hasattr(server, "loop"):  # started
        server.stop()


def moves(client: Client, first: int, count: int) -> None:
    """``count`` moves of joint 0, a frame each, 20 ms of the clock apart."""
    client.send("".join(f"move 0 {(first + k) / 1000}\nsleep 0.02\n" for k in range(count)))
    for _ in range(2 * count):
        assert client.read_line() == "ok"


def finished(server: ServerThread) -> list[Recorded]:
    """Wait for every recording to be finished and in place; what they gave."""
    return server.call_async(server.services.recordings.close("the test"))


def header_and_body(txt: Path) -> tuple[int, float, int, float]:
    """(header's frames, header's seconds, ``joints`` lines, the body's ``sleep`` sum)."""
    lines = txt.read_text().splitlines()
    recorded = next(line for line in lines if line.startswith("# recorded: "))
    seconds, frames = recorded.split(", ")[1:3]
    joints = sum(line.startswith("joints ") for line in lines)
    slept = sum(float(line.split()[1]) for line in lines if line.startswith("sleep "))
    return int(frames.split()[0]), float(seconds.split()[0]), joints, slept


def private_files(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir() if p.name.startswith("."))


def test_the_header_counts_what_the_body_kept(virtual_server: ServerThread, tmp_path: Path):
    """The body's file fills (a real ENOSPC: its descriptor now writes to /dev/full) with
    frames still in its buffer: they never reach the disk, and the header does not count
    them (it once said 288 frames over a body of 213 ``joints`` lines)."""
    (tmp_path / "rec").mkdir()
    server = virtual_server.start()
    client = Client(server.host, server.port, timeout=60.0)
    assert client.ask("record full").startswith("ok recording full")
    moves(client, 0, 100)  # two seconds of the clock: flushed at least once

    def fill_the_body() -> None:
        recorder = server.services.recordings.current
        assert recorder is not None
        full = os.open("/dev/full", os.O_WRONLY)
        os.dup2(full, recorder._body.fileno())
        os.close(full)

    server.call(fill_the_body)
    moves(client, 100, 100)  # the next flush fails: the recording stops
    assert client.ask("record") == "ok not recording"
    (done,) = finished(server)
    client.close()
    txt = tmp_path / "rec" / "full.txt"
    frames, seconds, joints, slept = header_and_body(txt)
    assert "# stopped early: write error: No space left on device" in txt.read_text()
    assert 0 < joints < 200 and frames == joints == done.frames
    assert seconds == pytest.approx(slept, abs=1e-3) and done.duration_s == pytest.approx(slept)
    assert private_files(tmp_path / "rec") == []


class FillingWriter:
    """A text file whose disk fills after ``room`` characters: ``ENOSPC`` from then on."""

    def __init__(self, file: TextIO, room: int) -> None:
        self.file = file
        self.room = room

    def write(self, text: str) -> int:
        if len(text) > self.room:
            self.file.write(text[: self.room])
            self.room = 0
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        self.room -= len(text)
        return self.file.write(text)

    def __enter__(self) -> FillingWriter:
        return self

    def __exit__(self, *exc: object) -> None:
        self.file.close()


def test_a_page_that_does_not_fit_is_not_written_and_leaves_no_part(
    virtual_server: ServerThread,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    caplog: pytest.LogCaptureFixture,
):
    """The disk fills 100 kB into the page: no NAME.html, no ``.part`` of it, a warning that
    says why, and the other files in place (they left a 729 KB ``.part`` on the disk)."""
    (tmp_path / "rec").mkdir()
    monkeypatch.setattr(record_page, "_sink", lambda file: FillingWriter(file, 100_000))
    server = virtual_server.start()
    client = Client(server.host, server.port, timeout=60.0)
    assert client.ask("record take").startswith("ok recording take")
    moves(client, 0, 10)
    with caplog.at_level(logging.WARNING, logger="c2rviz.record"):
        reply = client.ask("record stop")
    client.close()
    assert reply.startswith("ok recorded take: 11 frames") and "take.html" not in reply
    folder = tmp_path / "rec"
    assert sorted(p.name for p in folder.iterdir()) == ["take", "take.csv", "take.txt"]
    assert [r.getMessage() for r in caplog.records] == [
        "recording take: no page written (take.html): No space left on device; its other "
        "files stand"
    ]


@contextlib.contextmanager
def small_disk(at: Path, size: str) -> Iterator[Path]:
    """A tmpfs of ``size`` mounted at ``at`` (skips the test where mounting is not allowed)."""
    at.mkdir()
    if shutil.which("mount") is None or os.geteuid() != 0:
        pytest.skip("mounting a tmpfs needs root and mount(8)")
    mounted = subprocess.run(
        ["mount", "-t", "tmpfs", "-o", f"size={size}", "tmpfs", str(at)],
        capture_output=True,
        text=True,
    )
    if mounted.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here: {mounted.stderr.strip()}")
    try:
        yield at
    finally:
        subprocess.run(["umount", "-l", str(at)], check=False)


def fill(disk: Path, name: str) -> None:
    """Write ``name`` on ``disk`` until the disk is full."""
    with contextlib.suppress(OSError), open(disk / name, "ab", buffering=0) as filler:
        while True:
            filler.write(b"\0" * 65536)


def test_a_real_full_disk_leaves_every_file_whole_or_absent(tmp_path: Path, caplog):
    """A 4 MB tmpfs filled by another writer mid-recording, and again while the page is
    written: the txt (header true), csv and bag in place, no page and no part of one."""
    with small_disk(tmp_path / "disk", "4m") as disk:
        server = ServerThread(
            load_robot("motoman_sia20d"), ServerLimits(), clock=VirtualClock(), record_dir=disk
        )
        server.start()
        try:

            def page_on_a_full_disk(recorded: Recorded, state: RobotState) -> Path:
                fill(disk, "filler-2")  # whatever the ended bag gave back is taken again
                return write_page(recorded, state)

            server.call(
                lambda: setattr(server.services.recordings, "exporters", (page_on_a_full_disk,))
            )
            client = Client(server.host, server.port, timeout=60.0)
            assert client.ask("record full").startswith("ok recording full")
            moves(client, 0, 100)
            fill(disk, "filler-1")
            with caplog.at_level(logging.WARNING):
                sent = 100
                while client.ask("record") != "ok not recording":
                    moves(client, sent, 100)
                    sent += 100
                    assert sent < 10_000, "the disk never filled"
                finished(server)
            client.close()
        finally:
            server.stop()
        names = sorted(p.name for p in disk.iterdir())
        assert names == ["filler-1", "filler-2", "full", "full.csv", "full.txt"], names
        frames, seconds, joints, slept = header_and_body(disk / "full.txt")
        assert frames == joints and seconds == pytest.approx(slept, abs=1e-3)
        assert (disk / "full.csv").read_text().endswith("\n")
        assert "recording full: no page written (full.html): No space left on device; its " \
            "other files stand" in [r.getMessage() for r in caplog.records]  # fmt: skip
