"""The page in a process of its own (``--page-process``, issue 40): the channel, a page
process killed mid-move (commands go on, the page comes back), a late tab, the guards,
``--no-viewer``. The page in real Chromium through the new channel: tests/browser/
test_browser_page_process.py."""

from __future__ import annotations

import asyncio
import os
import signal
import socket
import time
import urllib.error
import urllib.request
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from page_ws import gui_values, node_names, scene_messages

from c2rviz.view.page_channel import MAX_MESSAGE, ChannelError, FrameReader, encode

DEADLINE_S = 120.0


# the channel


def test_messages_come_whole_however_the_bytes_are_cut() -> None:
    sent = [["frame", 1.5, [["r", [[1.0, 0.1, 0.2]], 0.0, [0.1], True, 0.3, 50.0]], []]]
    sent += [["line", "r", "move 0 30.0"], ["stop"]]
    data = b"".join(encode(m) for m in sent)
    reader = FrameReader()
    got = []
    for k in range(0, len(data), 3):
        got += reader.feed(data[k : k + 3])
    assert got == sent


def test_numpy_numbers_go_as_plain_ones() -> None:
    """A joint value may be a ``np.float64`` (a plan's sample): it goes, as a float."""
    import numpy as np

    message = ["frame", 0.5, [["r", [[np.float64(0.5), *np.zeros(2)]]]], np.arange(2)]
    assert FrameReader().feed(encode(message)) == [
        ["frame", 0.5, [["r", [[0.5, 0.0, 0.0]]]], [0, 1]]
    ]
    with pytest.raises(ChannelError, match="cannot carry object"):
        encode(["frame", object()])


def test_a_message_that_is_not_one_ends_the_channel() -> None:
    with pytest.raises(ChannelError, match="over"):
        FrameReader().feed((MAX_MESSAGE + 1).to_bytes(4, "big"))
    with pytest.raises(ChannelError, match="not msgpack"):
        FrameReader().feed((2).to_bytes(4, "big") + b"\xc1\xc1")
    with pytest.raises(ChannelError, match="kind"):
        FrameReader().feed(encode([1, 2]))


# the program


def children(pid: int) -> list[int]:
    """The processes whose parent is ``pid``."""
    out = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                stat = (entry / "stat").read_text()
            except OSError:
                continue
            if int(stat.rsplit(")", 1)[1].split()[1]) == pid:
                out.append(int(entry.name))
    return out


def page_process(pid: int, but: int | None = None) -> int:
    """The page process of the program ``pid`` (other than ``but``), once it runs: its one
    child (forked at start, so named as the program is; spawned on a restart)."""
    deadline = time.monotonic() + DEADLINE_S
    while time.monotonic() < deadline:
        for child in children(pid):
            try:
                state = Path(f"/proc/{child}/stat").read_text().rsplit(")", 1)[1].split()[0]
            except OSError:
                continue
            if child != but and state != "Z":
                return child
        time.sleep(0.05)
    raise AssertionError("no page process")


class Tcp:
    def __init__(self, port: int) -> None:
        self.sock = socket.create_connection(("127.0.0.1", port), timeout=DEADLINE_S)
        self.file = self.sock.makefile("rb")

    def send(self, line: str) -> None:
        self.sock.sendall(line.encode() + b"\n")

    def reply(self) -> str:
        return self.file.readline().decode().strip()

    def ask(self, line: str) -> str:
        self.send(line)
        return self.reply()

    def close(self) -> None:
        self.file.close()
        self.sock.close()


def policies(pid: int) -> set[int]:
    """The scheduling policies of the threads of process ``pid``."""
    return {os.sched_getscheduler(int(tid)) for tid in os.listdir(f"/proc/{pid}/task")}


def read_until(proc: Any, text: str) -> list[str]:
    """The program's output lines up to the first that holds ``text``."""
    seen = []
    while True:
        line = proc.popen.stdout.readline()
        assert line, f"the program ended before saying {text!r}: {seen}"
        seen.append(line)
        if text in line:
            return seen


def scene(url: str) -> list[dict[str, Any]]:
    """What a tab opened now gets, retried while the page is not served yet."""
    from websockets.exceptions import WebSocketException

    deadline = time.monotonic() + DEADLINE_S
    while True:
        try:
            return asyncio.run(scene_messages(url))
        except (OSError, WebSocketException):  # not listening yet, or starting
            assert time.monotonic() < deadline, "the page did not come back"
            time.sleep(0.2)


def test_a_killed_page_process_comes_back_and_commands_go_on(
    c2rviz_process: Callable[..., Any],
) -> None:
    proc = c2rviz_process("--viser-port", "0", "--page-process")
    first = page_process(proc.popen.pid)
    assert policies(first) == {os.SCHED_BATCH}  # the page's threads never preempt commands
    mover, bystander = Tcp(proc.port), Tcp(proc.port)
    try:
        for line in ("degrees", "motion on", "speed 20", "marker cube", "mark"):
            assert mover.ask(line) == "ok"
        # ok when it arrives: 7 s at speed 20 (28 s at speed 5, once), ample for the kill
        # and a bystander's `where` mid-move
        mover.send("move 0 90")
        os.kill(first, signal.SIGKILL)
        assert bystander.ask("where").startswith("ok ")  # mid-move, the page gone
        assert mover.reply() == "ok"  # the move went on to its end
        assert mover.ask("where") == "ok 90,0,0,0,0,0,0"
        said = "".join(read_until(proc, "starting it again"))
        assert "the page process stopped (status -9)" in said
        second = page_process(proc.popen.pid, but=first)
        assert b"c2rviz.view.page_process" in Path(f"/proc/{second}/cmdline").read_bytes()
        assert bystander.ask("mark") == "ok"
        # A tab opened now, on the same URL, gets the whole scene: the robot where it
        # is, both markers, the last commands. (A tab that came before the new page
        # process applied the frame with the second marker sees it once the frame is
        # applied: a later tab is opened until then.)
        both = {"/markers/motoman_sia20d/cube", "/markers/motoman_sia20d/sphere"}
        deadline = time.monotonic() + DEADLINE_S
        # (the markers and the readouts come in frames of their own: wait for both)
        while not (
            both <= node_names(messages := scene(proc.viewer_url))
            and "move 0 90" in gui_values(messages).get("Last commands", "")
        ):
            assert time.monotonic() < deadline, (node_names(messages), gui_values(messages))
            time.sleep(0.1)
        values = gui_values(messages)
        assert values["joint_s"] == pytest.approx(90.0)
        assert "move 0 90" in values["Last commands"]
        names = node_names(messages)
        assert any(n.startswith("/robots/motoman_sia20d/links/") for n in names)
        assert policies(second) == {os.SCHED_BATCH}  # spawned, not forked: the same
    finally:
        mover.close()
        bystander.close()
    proc.popen.send_signal(signal.SIGTERM)
    assert proc.wait() == 0
    assert "c2rviz: stopped" in "".join(read_until(proc, "stopped"))
    assert all(p != second for p in children(proc.popen.pid))


def test_the_page_process_keeps_the_door_guards(c2rviz_process: Callable[..., Any]) -> None:
    """The token and the origin check are the page's own, unchanged: checked in the page
    process now."""
    import viser
    import websockets

    proc = c2rviz_process("--viser-port", "0", "--page-process", "--viewer-token", "s3cret")
    url = proc.viewer_url
    assert "?token=s3cret" in url
    base = url.split("/?")[0]
    with pytest.raises(urllib.error.HTTPError) as refused:
        urllib.request.urlopen(base, timeout=DEADLINE_S)
    assert refused.value.code == 403
    refused.value.close()
    with urllib.request.urlopen(url, timeout=DEADLINE_S) as page:
        assert page.status == 200

    async def open_socket(origin: str) -> str:
        ws_url = base.replace("http://", "ws://") + "/?token=s3cret"
        try:
            async with websockets.connect(
                ws_url,
                subprotocols=[websockets.Subprotocol(f"viser-v{viser.__version__}")],
                origin=websockets.Origin(origin),
                open_timeout=DEADLINE_S,
            ):
                return "open"
        except websockets.InvalidStatus as exc:
            return str(exc.response.status_code)

    assert asyncio.run(open_socket("http://elsewhere.example")) == "403"
    assert asyncio.run(open_socket(base)) == "open"
    messages = scene(url)
    assert "joint_s" in gui_values(messages)


def test_no_viewer_starts_no_page_process(c2rviz_process: Callable[..., Any]) -> None:
    proc = c2rviz_process("--no-viewer", "--page-process")
    tcp = Tcp(proc.port)
    try:
        assert tcp.ask("where") == "ok 0,0,0,0,0,0,0"
    finally:
        tcp.close()
    assert children(proc.popen.pid) == []


def test_a_page_that_cannot_be_served_stops_the_program_as_before(tmp_path: Path) -> None:
    """An address the page cannot listen on: one sentence, status 2, no process left."""
    import subprocess
    import sys

    from support import ROOT

    done = subprocess.run(
        [sys.executable, "-m", "c2rviz", "--port", "0", "--no-crcl", "--no-rosbridge"]
        + ["--viser-host", "203.0.113.7", "--viser-port", "0", "--page-process"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=DEADLINE_S,
    )
    assert done.returncode == 2, done
    assert "c2rviz: cannot serve the viewer on 203.0.113.7:0:" in done.stderr
    assert "viewer at" not in done.stdout


def test_the_program_side_never_loads_viser() -> None:
    """With ``--page-process`` viser lives in the page process only; the two processes'
    readouts keep the same number of last commands."""
    import subprocess
    import sys

    from c2rviz.view import page_snapshot, panel

    assert page_snapshot.RECENT_COMMANDS == panel.RECENT_COMMANDS
    check = (
        "import sys, c2rviz.app.program, c2rviz.view.page_link; sys.exit('viser' in sys.modules)"
    )
    assert subprocess.run([sys.executable, "-c", check], timeout=DEADLINE_S).returncode == 0


# the ini key and the early start


def test_the_ini_key_serves_the_page_from_its_own_process(
    c2rviz_process: Callable[..., Any], tmp_path: Path
) -> None:
    ini = tmp_path / "cmdinterpreter.ini"
    ini.write_text("[options]\npage_process = on\n")
    proc = c2rviz_process("--config", str(ini), "--viser-port", "0")
    assert page_process(proc.popen.pid)
    assert "joint_s" in gui_values(scene(proc.viewer_url))
    ini.write_text("[options]\npage_process = off\n")
    proc = c2rviz_process("--config", str(ini), "--viser-port", "0")
    assert children(proc.popen.pid) == []  # the page in the program's own process


def test_a_bad_ini_value_names_the_choices(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from c2rviz.app.cli import main

    ini = tmp_path / "cmdinterpreter.ini"
    ini.write_text("[options]\npage_process = yes\n")
    assert main(["--config", str(ini), "--port", "0"]) == 2
    said = capsys.readouterr().err
    assert "[options] page_process = 'yes' is not one" in said and "off, on" in said, said
    assert not [c for c in children(os.getpid()) if is_page_process(c)]


def test_a_forked_page_process_ends_when_the_program_does_not_start(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """The page process is forked before the loop starts; a program that then cannot open
    a door (its command port taken) closes it: none is left behind."""
    from c2rviz.app import cli
    from c2rviz.view import page_start

    started: list[page_start.Spawned | None] = []
    fork = page_start.fork

    def counted() -> page_start.Spawned | None:
        started.append(fork())
        return started[-1]

    monkeypatch.setattr(page_start, "fork", counted)
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = str(taken.getsockname()[1])
        assert cli.main(["--page-process", "--port", port, "--no-crcl", "--no-rosbridge"]) == 2
    assert "the port is in use" in capsys.readouterr().err
    assert len(started) == 1 and started[0] is not None
    process, _ = started[0]
    assert process.poll() is not None  # it ended: no page process left
    assert process.pid not in children(os.getpid())


def is_page_process(pid: int) -> bool:
    try:
        return b"c2rviz.view.page_process" in Path(f"/proc/{pid}/cmdline").read_bytes()
    except OSError:
        return False
