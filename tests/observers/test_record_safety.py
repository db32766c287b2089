"""Recordings lose nothing (issue 23, items 1, 4 and 5).

- Two clients racing `record stop` and `record NAME overwrite` on one name: each
  recording is complete when its stop is answered, and the later one holds the names.
- A recording never writes through a symbolic link: a name whose file is a link is
  refused, and a link planted where the old private files went changes nothing.
- Stopping the program by `quit`, SIGINT or SIGTERM, with a client gone mid-`sleep`,
  finishes the recording whole: the command file checks, the CSV, page and bag are there.
"""

from __future__ import annotations

import csv
import os
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable
from pathlib import Path

import pytest
from rosbags.highlevel import AnyReader
from support import Client, Process, ServerThread

from c2rviz.app.cli import main
from c2rviz.app.program import write_page
from c2rviz.clients import player
from c2rviz.observers.recorded import Recorded
from c2rviz.world.state import RobotState


def record_into(server: ServerThread, folder: Path) -> None:
    server.call(lambda: setattr(server.services.recordings, "folder", folder))


def frames_of(folder: Path, name: str) -> tuple[int, int, int]:
    """(`joints` lines of NAME.txt, rows of NAME.csv, /joint_states of the bag NAME/)."""
    script = player.load_script(folder / f"{name}.txt")
    assert script.problems == []
    joints = sum(line.wire.startswith("joints") for line in script.lines)
    with open(folder / f"{name}.csv", newline="") as file:
        rows = len(list(csv.reader(file))) - 1
    with AnyReader([folder / name]) as reader:
        states = sum(c.msgcount for c in reader.connections if c.topic == "/joint_states")
    return joints, rows, states


@pytest.mark.wall_clock
def test_racing_stop_and_overwrite_lose_neither(
    start_server: Callable[..., ServerThread], connect: Callable[..., Client], tmp_path: Path
):
    server = start_server()
    record_into(server, tmp_path)
    desk = server.services.recordings
    release = threading.Event()

    def held_page(recorded: Recorded, state: RobotState) -> Path:
        """The page, then a wait: A's recording is still finishing when B starts."""
        path = write_page(recorded, state)
        release.wait(timeout=60)
        return path

    server.call(lambda: setattr(desk, "exporters", (held_page,)))
    a, b = connect(server), connect(server)
    assert a.ask("record race").startswith("ok recording race")
    for k in range(400):  # 400 frames' worth of states, each in a frame of its own
        a.send(f"move 0 {k / 1000}\nsleep 0.011\n")
    for _ in range(800):
        assert a.read_line() == "ok"
    a.send("record stop\n")
    while server.call(lambda: bool(desk.running)):
        time.sleep(0.001)
    # A's recording is being finished; B records the same name over it.
    assert b.ask("record race overwrite").startswith("ok recording race")
    assert b.ask("move 1 0.2") == "ok"
    release.set()
    stopped = a.read_line()
    frames = int(stopped.split(": ")[1].split()[0])
    assert stopped.startswith("ok recorded race: ") and frames > 200
    assert frames_of(tmp_path, "race") == (frames, frames, frames)  # A's, whole
    again = b.ask("record stop")
    assert again.startswith("ok recorded race: ")
    later = int(again.split(": ")[1].split()[0])
    assert frames_of(tmp_path, "race") == (later, later, later)  # B's, whole
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "race",
        "race.csv",
        "race.html",
        "race.txt",
    ]  # no private file left behind


@pytest.mark.parametrize("suffix", [".csv", ".txt", ".html", ""])
def test_a_name_whose_file_is_a_link_is_refused(
    server: ServerThread, connect: Callable[..., Client], tmp_path: Path, suffix: str
):
    folder, outside = tmp_path / "rec", tmp_path / "outside"
    folder.mkdir()
    record_into(server, folder)
    (folder / f"evil{suffix}").symlink_to(outside)  # dangling: would create `outside`
    client = connect(server)
    assert client.ask("record evil overwrite") == (
        f"error: record: {folder / f'evil{suffix}'} is a symbolic link, and recordings never "
        "write through links; remove it or choose another name"
    )
    assert not outside.exists() and client.ask("record") == "ok not recording"


def test_links_at_the_old_private_names_change_nothing(
    server: ServerThread, connect: Callable[..., Client], tmp_path: Path
):
    folder = tmp_path / "rec"
    folder.mkdir()
    record_into(server, folder)
    victim = tmp_path / "victim"
    victim.write_text("keep me\n")
    for name in (".evil2.txt.part", ".evil2.txt.tmp", ".evil2.csv"):
        (folder / name).symlink_to(victim)
    client = connect(server)
    assert client.ask("record evil2").startswith("ok recording evil2")
    assert client.ask("move 0 0.1") == "ok"
    assert client.ask("record stop").startswith("ok recorded evil2: ")
    assert victim.read_text() == "keep me\n"
    assert frames_of(folder, "evil2")[0] >= 1


@pytest.mark.parametrize("how", ["quit", "SIGTERM", "SIGINT"])
def test_stopping_the_program_finishes_the_recording(
    c2rviz_process: Callable[..., Process], tmp_path: Path, how: str
):
    proc = c2rviz_process("--no-viewer", "--record-dir", str(tmp_path))
    mover, sleeper = Client("127.0.0.1", proc.port), Client("127.0.0.1", proc.port)
    try:
        assert mover.ask("record take").startswith("ok recording take")
        for line in ("motion on", "speed 100", "joints 0.4,0.3,0,0,0,0,0", "move 0 -0.2"):
            assert mover.ask(line) == "ok"
        mover.send("joints 0.8,-0.3,0,0,0,0,0\n")  # still moving when the program stops
        sleeper.send("sleep 100\n")
        time.sleep(0.2)
        sleeper.close()
        if how == "quit":
            quitter = Client("127.0.0.1", proc.port)
            assert quitter.ask("quit") == "ok"
            quitter.close()
        else:
            proc.popen.send_signal(getattr(signal, how))
        status = proc.wait()
    finally:
        mover.close()
    output = proc.popen.stdout.read()  # type: ignore[union-attr]
    assert status == 0 and "Traceback" not in output, output
    assert "c2rviz: recorded take: " in output
    joints, rows, states = frames_of(tmp_path, "take")
    assert joints == rows == states > 50
    assert (tmp_path / "take.html").stat().st_size > 0
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "take",
        "take.csv",
        "take.html",
        "take.txt",
    ]
    assert player.main([str(tmp_path / "take.txt"), "--check"]) == 0  # the file checks


def test_record_flag_says_what_it_records_and_may_overwrite(
    c2rviz_process: Callable[..., Process], tmp_path: Path, capsys: pytest.CaptureFixture[str]
):
    for name in ("run.txt", "run.csv"):
        (tmp_path / name).write_text("an older run\n")
    proc = c2rviz_process(
        "--no-viewer", "--record", "run", "--record-dir", str(tmp_path), "--record-overwrite"
    )
    assert f"c2rviz: recording run into {tmp_path.resolve()} until exit: run.txt, run.csv, " \
        "run.html and the bag run/\n" in proc.output  # fmt: skip
    client = Client("127.0.0.1", proc.port)
    assert client.ask("quit") == "ok"
    client.close()
    assert proc.wait() == 0
    assert frames_of(tmp_path, "run")[0] == 1
    with pytest.raises(SystemExit) as helped:  # `c2rviz --help`, read in this process
        main(["--help"])
    assert helped.value.code == 0
    text = " ".join(capsys.readouterr().out.split())
    for named in ("NAME.txt", "NAME.csv", "NAME.html", "NAME/", "--record-overwrite"):
        assert named in text, named


@pytest.mark.xdist_group("default_ports")  # binds a default port: one at a time
def test_a_file_size_limit_ends_the_recording_readable(tmp_path: Path):
    """A real kernel write error (RLIMIT_FSIZE: EFBIG) mid-recording: the recording stops
    with an event, the server goes on, and every file is whole up to the error, in place."""

    def limited() -> None:  # in the child, before exec: both survive it
        import resource

        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (2_500_000, resource.RLIM_INFINITY))

    popen = subprocess.Popen(
        [sys.executable, "-m", "c2rviz", "--no-viewer", "--port", "0", "--hz", "1000"]
        + ["--record-dir", str(tmp_path)],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        preexec_fn=limited,
        env={**os.environ, "PYTHONUNBUFFERED": "1"},
    )
    try:
        assert popen.stdout is not None
        port = None
        while port is None:
            line = popen.stdout.readline()
            assert line, "c2rviz did not start"
            if "commands on" in line:
                port = int(line.split("commands on ")[1].split(":")[1].split()[0])
        watcher, client = Client("127.0.0.1", port), Client("127.0.0.1", port)
        assert watcher.ask("watch 1") == "ok"
        assert client.ask("record big").startswith("ok recording big")
        sent = 0
        while True:  # a new state every 2 ms: a frame each, until the bag is too big
            client.send("".join(f"move 0 {(sent + k) % 1000 / 2000}\nsleep 0.002\n"
                                for k in range(100)))  # fmt: skip
            for _ in range(200):
                assert client.read_line() == "ok"
            sent += 100
            if client.ask("record") == "ok not recording":
                break
            assert sent < 20_000, "the bag never reached the limit"
        seen = ""
        while not seen.startswith("event record-stopped"):
            seen = watcher.read_line()
        assert seen == "event record-stopped big: write error: File too large"
        assert client.ask("move 0 0.3") == "ok"  # the server goes on
        deadline = time.monotonic() + 60
        while not (tmp_path / "big.html").exists() and time.monotonic() < deadline:
            time.sleep(0.05)
        assert client.ask("quit") == "ok"
        watcher.close()
        client.close()
        status = popen.wait(timeout=60)
    finally:
        if popen.poll() is None:
            popen.kill()
        output, _ = popen.communicate(timeout=60)
    assert status == 0 and "Traceback" not in output, output
    joints, rows, states = frames_of(tmp_path, "big")
    assert 0 < states <= rows and joints == rows > 500  # the bag keeps its whole chunks
    assert "# stopped early: write error: File too large" in (tmp_path / "big.txt").read_text()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["big", "big.csv", "big.html", "big.txt"]


def test_overwrite_replaces_only_a_recording(
    server: ServerThread, connect: Callable[..., Client], tmp_path: Path
):
    record_into(server, tmp_path)
    (tmp_path / "data").mkdir()
    (tmp_path / "data" / "notes.txt").write_text("mine\n")
    client = connect(server)
    assert client.ask("record data overwrite") == (
        f"error: record: {tmp_path / 'data'} is a folder that is not a recording's bag, and "
        "'overwrite' replaces only recordings; move it or choose another name"
    )
    assert (tmp_path / "data" / "notes.txt").read_text() == "mine\n"
    for _ in range(2):  # a recording's own bag is replaced
        assert client.ask("record take overwrite").startswith("ok recording take")
        assert client.ask("record stop").startswith("ok recorded take: ")
    assert sorted(p.name for p in (tmp_path / "take").iterdir()) == ["metadata.yaml", "take.mcap"]
