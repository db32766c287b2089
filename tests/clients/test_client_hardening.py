"""The clients against servers that misbehave, and files that are large or wrong (issue 23
item 12, issue 30 items 3 and 9).

A misbehaving "server" here is a plain socket thread: one that streams without newlines,
one that answers like a web server, one that puts terminal escape sequences in its replies.
"""

from __future__ import annotations

import contextlib
import os
import resource
import socket
import subprocess
import sys
import threading
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest
from support import ROOT

from c2rviz.clients import player
from c2rviz.clients.client import Client
from c2rviz.clients.connection import find_script, recording_folder
from c2rviz.clients.errors import ReplyTooLong, UnexpectedReply
from c2rviz.clients.script import MAX_PROBLEMS, load_script
from c2rviz.clients.stream import shown

ENV = {**os.environ, "PYTHONUNBUFFERED": "1", "PYTHONPATH": str(ROOT)}  # this tree's c2rviz
REPL_SCRIPT = str(ROOT / "clients" / "socketcmdline.py")
PLAYER_SCRIPT = str(ROOT / "clients" / "fileplayer.py")


class FakeServer:
    """A listening socket whose one client is served by ``serve(conn)`` on a thread."""

    def __init__(self, serve: Callable[[socket.socket], None]) -> None:
        self.sock = socket.create_server(("127.0.0.1", 0))
        self.port = self.sock.getsockname()[1]
        self.sent = 0
        self.thread = threading.Thread(target=self._run, args=(serve,), daemon=True)
        self.thread.start()

    def _run(self, serve: Callable[[socket.socket], None]) -> None:
        conn, _ = self.sock.accept()
        with conn, contextlib.suppress(OSError):  # the client closed: what a test wants
            serve(conn)

    def close(self) -> None:
        self.sock.close()
        self.thread.join(timeout=60)


@pytest.fixture
def fake() -> Iterator[Callable[[Callable[[socket.socket], None]], FakeServer]]:
    made: list[FakeServer] = []

    def start(serve: Callable[[socket.socket], None]) -> FakeServer:
        made.append(FakeServer(serve))
        return made[-1]

    yield start
    for server in made:
        server.close()


def run(script: str, *args: str, stdin: str = "") -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, script, *args],
        input=stdin,
        capture_output=True,
        text=True,
        timeout=120,
        env=ENV,
    )


def test_a_server_streaming_without_newlines_cannot_grow_the_client(fake):
    """The client reads at most its line limit (1 MiB) of an unfinished line, then closes."""
    chunk = b"x" * 65536

    def flood(conn: socket.socket) -> None:
        conn.recv(100)
        while server.sent < 200 * len(chunk):  # 12.5 MiB, if nobody stops us
            conn.sendall(chunk)
            server.sent += len(chunk)

    server = fake(flood)
    client = Client("127.0.0.1", server.port, retry_s=5)
    with pytest.raises(ReplyTooLong, match="over the client's limit of 1048576 bytes"):
        client.ask("names")
    assert not client.is_open
    server.thread.join(timeout=60)
    # What the server got rid of before it saw the connection closed: the limit, plus what
    # the kernel's socket buffers held.
    assert server.sent < 200 * len(chunk)


def test_c2rviz_cli_says_a_flooding_server_is_not_c2rviz(fake):
    def flood(conn: socket.socket) -> None:
        conn.recv(100)
        for _ in range(200):
            conn.sendall(b"y" * 65536)

    server = fake(flood)
    done = run(REPL_SCRIPT, "--port", str(server.port), stdin="where\n")
    assert done.returncode == 1
    assert "is not a c2rviz server" in done.stdout + done.stderr
    assert "Traceback" not in done.stderr


def test_c2rviz_cli_says_a_web_server_is_not_c2rviz(fake):
    def web(conn: socket.socket) -> None:
        conn.recv(100)
        conn.sendall(b"HTTP/1.1 400 Bad Request\r\nContent-Length: 0\r\n\r\n")

    server = fake(web)
    done = run(REPL_SCRIPT, "--port", str(server.port), stdin="where\n")
    assert done.returncode == 1
    said = done.stdout + done.stderr
    assert f"127.0.0.1:{server.port} is not a c2rviz server" in said
    assert "'HTTP/1.1 400 Bad Request'" in said
    assert "Traceback" not in done.stderr


def test_the_player_says_a_web_server_is_not_c2rviz(fake, tmp_path):
    def web(conn: socket.socket) -> None:
        conn.recv(100)
        conn.sendall(b"HTTP/1.1 400 Bad Request\r\n\r\n")

    server = fake(web)
    path = tmp_path / "one.txt"
    path.write_text("home\n")
    done = run(PLAYER_SCRIPT, str(path), "--port", str(server.port))
    assert done.returncode == 1
    assert "is not a c2rviz reply" in done.stderr and "Traceback" not in done.stderr


ESCAPES = "ok \x1b[2J\x1b]0;pwned\x07 \u202eevil \x9b31m"


def test_terminal_escape_sequences_from_the_server_are_shown_escaped(fake):
    def hostile(conn: socket.socket) -> None:
        reader = conn.makefile("rb")
        reader.readline()
        conn.sendall(b"ok motoman_sia20d joint_s\n")  # names
        reader.readline()
        conn.sendall(ESCAPES.encode() + b"\n")
        reader.readline()

    server = fake(hostile)
    done = run(REPL_SCRIPT, "--port", str(server.port), stdin="pose\n")
    assert "\x1b" not in done.stdout and "\x07" not in done.stdout and "\u202e" not in done.stdout
    assert "ok \\x1b[2J\\x1b]0;pwned\\x07 \\u202eevil \\x9b31m" in done.stdout


def test_shown_escapes_controls_and_keeps_text():
    assert shown("ok 1,2,3") == "ok 1,2,3"
    assert shown("é\tü") == "é\tü"
    assert shown("\x00\x7f\U000e0001") == "\\x00\\x7f\\U000e0001"


def test_the_check_lists_every_bad_line(tmp_path, capsys):
    path = tmp_path / "typos.txt"
    path.write_text("home\nmvoe 1 2\nwhere\njonts 1\njoints 1,,2\nsleep -1\n")
    assert player.main([str(path), "--check"]) == 2
    err = capsys.readouterr().err
    for line in (2, 4, 5, 6):
        assert f"{path}:{line}: error:" in err
    assert f"{path}: 4 problems; nothing was sent" in err


def test_a_file_of_nothing_but_errors_is_listed_up_to_the_limit(tmp_path):
    path = tmp_path / "junk.txt"
    path.write_text("frob\n" * (MAX_PROBLEMS + 50))
    script = load_script(path)
    problems = script.all_problems()
    assert len(problems) == MAX_PROBLEMS + 1
    assert problems[-1] == f"{path}: ... and 50 more"


def test_robot_problems_are_listed_for_every_line(server, tmp_path, capsys):
    path = tmp_path / "counts.txt"
    path.write_text("joints 1,2\nhome\njoints 1,2,3\nmove 9 1\njoints 0,0,0,0,0,0,0\n")
    assert player.main([str(path), "--port", str(server.port)]) == 2
    err = capsys.readouterr().err
    assert f"{path}:1: error: joints needs 7 values, got 2" in err
    assert f"{path}:3: error: joints needs 7 values, got 3" in err
    assert f"{path}:4: error: joint index 9 out of range" in err
    assert server.scene.commands == ["names"]  # nothing moved


def test_files_are_found_here_then_in_the_recording_folder_then_commands(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    ini = tmp_path / "cmdinterpreter.ini"
    ini.write_text("[options]\nrecord_dir = takes\n")
    (tmp_path / "takes").mkdir()
    (tmp_path / "takes" / "demo.txt").write_text("home\n")
    assert recording_folder() == tmp_path / "takes"
    assert find_script("demo.txt") == tmp_path / "takes" / "demo.txt"
    assert find_script("motoman.txt") == ROOT / "commands" / "motoman.txt"
    (tmp_path / "motoman.txt").write_text("home\n")
    assert find_script("motoman.txt") == Path("motoman.txt")  # the working directory first
    with pytest.raises(FileNotFoundError) as caught:
        find_script("nonesuch.txt")
    said = str(caught.value)
    for place in (tmp_path, tmp_path / "takes", ROOT / "commands"):
        assert str(place / "nonesuch.txt") in said


def test_without_a_users_ini_the_recording_folder_is_the_working_directorys(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # no ini here: the project's own is read, and does not count
    assert recording_folder() == tmp_path / "recordings"


def test_the_player_says_where_it_found_a_recording(server, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "recordings").mkdir()
    (tmp_path / "recordings" / "take.txt").write_text("home\n")
    assert player.main(["take.txt", "--port", str(server.port)]) == 0
    assert f"playing {tmp_path / 'recordings' / 'take.txt'}" in capsys.readouterr().err


def test_a_reply_that_is_not_utf8_is_an_error_and_the_stream_stays_in_step(fake):
    def latin(conn: socket.socket) -> None:
        reader = conn.makefile("rb")
        reader.readline()
        conn.sendall(b"ok caf\xe9\n")
        reader.readline()
        conn.sendall(b"ok 1\n")
        reader.readline()

    server = fake(latin)
    client = Client("127.0.0.1", server.port)
    with pytest.raises(UnexpectedReply, match="not UTF-8"):
        client.ask("where")
    assert client.ask("where") == "ok 1"
    client.close()


def _peak_rss_mb(args: list[str]) -> tuple[int, float]:
    """Run ``python ARGS`` alone in a child; its status and peak resident memory [MB]."""
    code = (
        "import resource, runpy, subprocess, sys\n"
        "done = subprocess.run(sys.argv[1:])\n"
        "peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss\n"
        "print(done.returncode, peak / 1024)\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code, sys.executable, *args],
        capture_output=True,
        text=True,
        timeout=600,
        check=True,
        env=ENV,
    )
    status, peak = out.stdout.split()[-2:]
    return int(status), float(peak)


@pytest.mark.wall_clock
@pytest.mark.timeout(600)  # 1.3 M lines parsed thrice: past 120 s at load 12 with coverage
def test_the_player_checks_and_streams_a_long_recording_in_flat_memory(server, tmp_path):
    """A 59 MB recording once took 347 MB to play; now memory does not grow with the file."""
    line = "joints 0.1234567890123,0.1,0.2,0.3,0.4,0.5,0.6\n"
    small, big = tmp_path / "small.txt", tmp_path / "big.txt"
    small.write_text("# robot: motoman_sia20d\nradians\n" + line * 1000)
    with big.open("w") as out:
        out.write("# robot: motoman_sia20d\nradians\n")
        block = line * 10000
        for _ in range(130):  # 1.3 M lines, 62 MB
            out.write(block)
    assert big.stat().st_size > 59e6
    base_status, base = _peak_rss_mb([PLAYER_SCRIPT, str(small), "--check"])
    status, peak = _peak_rss_mb([PLAYER_SCRIPT, str(big), "--check"])
    assert base_status == status == 0
    assert peak < base + 20, f"checking 62 MB took {peak:.0f} MB, a small file {base:.0f} MB"
    # And playing: the first lines of the big file go out before it is read again whole.
    script = load_script(big)
    lines = script.stream()
    first = next(lines)
    assert first.number == 2 and first.wire == "radians"
    lines.close()
    played_status, played = _peak_rss_mb(
        [PLAYER_SCRIPT, str(small), "--port", str(server.port), "--window", "64"]
    )
    assert played_status == 0 and played < base + 20
    assert resource.getrusage(resource.RUSAGE_SELF).ru_maxrss > 0
