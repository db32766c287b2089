"""Stopping: quit, SIGINT and SIGTERM with clients mid-command, the port freed, and exposure."""

from __future__ import annotations

import select
import signal
import socket
import time
from collections.abc import Callable

import pytest

from c2rviz.protocol import replies

HOME = "ok 0,0,0,0,0,0,0"
MARKS = 10_000  # the flood a never-reading tab is not sent in full


def port_is_free(port: int) -> bool:
    """True when a new server could listen on ``port`` (as the server does: SO_REUSEADDR)."""
    with socket.socket() as probe:
        probe.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            probe.bind(("127.0.0.1", port))
            probe.listen()
        except OSError:
            return False
    return True


def wait_until(predicate: Callable[[], bool], timeout_s: float = 60.0) -> None:
    deadline = time.monotonic() + timeout_s
    while not predicate():
        assert time.monotonic() < deadline, "timed out"
        time.sleep(0.01)


def read_all(sock: socket.socket) -> list[str]:
    """Every reply line until the server closes the connection."""
    data = b""
    while chunk := sock.recv(65536):
        data += chunk
    return data.decode().splitlines()


def wait_answered(socks: list[socket.socket]) -> None:
    """Wait until each socket has a reply to read (the server has read its line), unread."""
    for sock in socks:
        ready, _, _ = select.select([sock], [], [], 60)
        assert ready, "the server did not answer in 60 s"


def open_clients(port: int) -> dict[str, list[socket.socket]]:
    """20 clients in every state a stop can find them in; each is answered once first."""
    kinds = {"idle": 8, "sleeping": 5, "partial": 4, "sent-bye": 1, "flooding": 2}
    clients: dict[str, list[socket.socket]] = {kind: [] for kind in kinds}
    for kind, count in kinds.items():
        for _ in range(count):
            sock = socket.socket()
            if kind == "flooding":
                sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
            sock.settimeout(10)
            sock.connect(("127.0.0.1", port))
            sock.sendall(b"where\n")
            assert sock.recv(100) == (HOME + "\n").encode()  # connected and served
            clients[kind].append(sock)
    for sock in clients["sleeping"]:  # a sleep with lines queued behind it
        sock.sendall(b"where\nsleep 30\nwhere\n# a comment\nmove 0 1\n")
        assert sock.recv(100) == (HOME + "\n").encode()  # read, so now asleep
    for sock in clients["partial"]:
        sock.sendall(b"move 0 0.")
    for sock in clients["sent-bye"]:
        sock.sendall(b"bye\n")
    for sock in clients["flooding"]:  # ~8 MB of replies never read: more than the kernel holds
        sock.sendall(b"help\n" * 30_000)
    return clients


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_a_signal_stops_promptly_with_20_clients(c2rviz_process, sig):
    proc = c2rviz_process("--no-viewer", "--max-unread", str(64 << 20))  # floods stay connected
    clients = open_clients(proc.port)
    wait_answered(clients["sent-bye"])  # the server has read what was sent
    start = time.monotonic()
    proc.popen.send_signal(sig)
    # A hang guard, not a figure: that it did not wait out the 30 s sleeps is their
    # replies below (`shutting down`, not `ok`), whatever the machine's load.
    assert proc.wait(timeout=120) == 0
    took = time.monotonic() - start
    print(f"{sig.name}: stopped {took:.2f} s after the signal, 20 clients connected")
    for sock in clients["idle"]:
        assert read_all(sock) == []  # nothing unanswered: just closed
    for sock in clients["sleeping"]:  # the sleep and both queued commands are answered
        assert read_all(sock) == [replies.SHUTTING_DOWN] * 3
    for sock in clients["partial"]:
        assert read_all(sock) == []  # half a line is not a command
    for sock in clients["sent-bye"]:
        assert read_all(sock) == [replies.BYE]
    for sock in clients["flooding"]:
        sock.close()  # whatever it got, the program did not wait for it
    for group in clients.values():
        for sock in group:
            sock.close()
    assert port_is_free(proc.port)
    rest = proc.popen.stdout.read()
    assert "c2rviz: stopped" in rest
    assert "Traceback" not in rest and "warning" not in "".join(proc.output) + rest


def test_quit_answers_every_line_already_read_then_exits_cleanly(c2rviz_process):
    proc = c2rviz_process("--no-viewer")
    clients = open_clients(proc.port)
    quitter = socket.create_connection(("127.0.0.1", proc.port), timeout=60)
    wait_answered(clients["sent-bye"])  # the server has read what was sent
    quitter.sendall(b"where\nquit\nwhere\nhome\n")
    assert read_all(quitter) == [HOME, "ok", replies.SHUTTING_DOWN, replies.SHUTTING_DOWN]
    # A hang guard, not a figure: that it did not wait out the 30 s sleeps is their
    # replies below (`shutting down`, not `ok`), whatever the machine's load.
    assert proc.wait(timeout=120) == 0
    for sock in clients["sleeping"]:
        assert read_all(sock) == [replies.SHUTTING_DOWN] * 3
    for sock in clients["idle"] + clients["partial"]:
        assert read_all(sock) == []
    for group in clients.values():
        for sock in group:
            sock.close()
    quitter.close()
    assert port_is_free(proc.port)


def test_the_port_is_free_after_stop(start_server, connect):
    server = start_server()
    idle, sleeper = connect(server), connect(server)
    assert idle.ask("where") == HOME
    sleeper.send("sleep 30\nwhere\n")
    wait_until(lambda: "sleep 30" in server.call(lambda: list(server.scene.commands)))
    server.stop()
    assert idle.closed_by_server()
    assert sleeper.read_line() == replies.SHUTTING_DOWN
    assert sleeper.read_line() == replies.SHUTTING_DOWN
    assert sleeper.closed_by_server()
    assert port_is_free(server.port)


def test_a_client_arriving_during_stop_is_told_and_closed(start_server, connect):
    server = start_server()
    server.call(lambda: setattr(server.server, "stopping", True))
    late = connect(server)
    assert late.read_line() == replies.SHUTTING_DOWN
    assert late.closed_by_server()


def test_binding_beyond_loopback_warns_and_needs_an_explicit_host(c2rviz_process):
    proc = c2rviz_process("--host", "0.0.0.0", "--no-viewer")
    assert any("commands on 0.0.0.0:" in line for line in proc.output)
    warning = proc.popen.stdout.readline()
    if warning.startswith("c2rviz: CRCL on 0.0.0.0:"):  # the CRCL door's line comes first
        warning = proc.popen.stdout.readline()
    assert warning.startswith("c2rviz: warning: the command server listens on 0.0.0.0")
    assert "anyone who can reach it can move the robot and stop the program" in warning
    with socket.create_connection(("127.0.0.1", proc.port), timeout=10) as sock:
        sock.sendall(b"where\nquit\n")
        assert read_all(sock) == [HOME, "ok"]
    assert proc.wait(timeout=120) == 0  # a hang guard


def test_a_stop_mid_flood_answers_what_was_read_in_order(start_server):
    """Lines already read (run, waiting their turn, or buffered) are answered; then EOF."""
    import threading

    server = start_server()
    sock = socket.create_connection((server.host, server.port), timeout=10)
    replies_seen: list[str] = []
    reader = threading.Thread(target=lambda: replies_seen.extend(read_all(sock)))
    reader.start()
    sock.sendall(b"where\n" * 100_000)  # lands in kernel buffers; the server is still reading
    wait_until(lambda: server.call(lambda: len(server.scene.commands)) > 0)  # it has begun
    server.stop()
    reader.join(timeout=10)
    sock.close()
    answered = replies_seen.count(HOME)
    assert replies_seen  # without a reset (a reset raises in read_all), ...
    assert replies_seen[:answered] == [HOME] * answered  # ... in order: answers, then ...
    # ... the rest read before the stop (none, when a fast server had run them all).
    assert set(replies_seen[answered:]) <= {replies.SHUTTING_DOWN}
    assert len(replies_seen) <= 100_000
    print(f"stop mid-flood: {answered} answered, {len(replies_seen) - answered} shutting down")


@pytest.mark.parametrize("how", ["quit", "SIGINT", "SIGTERM", "SIGHUP"])
def test_every_way_to_stop_answers_and_exits_with_a_tab_that_never_reads(c2rviz_process, how):
    """With the viewer on: a tab that never reads (its TCP window shut after a flood of
    markers) holds nothing up; every line already read is answered; exit status 0."""
    from viewer_tabs import never_reading_tab

    proc = c2rviz_process("--viser-port", "0")
    viewer_port = int(proc.viewer_url.rsplit(":", 1)[1])
    tab = never_reading_tab(viewer_port)
    flooder = socket.create_connection(("127.0.0.1", proc.port), timeout=30)
    # ~10 frames of 1000 markers for the tab not to read: some 240 KB, far more than its
    # 4 KB window takes, so the window is shut and the viewer holds unsent frames (60 000
    # marks held nothing more up: the kernel took their 2.8 MB all the same).
    marks = "".join(f"mark {i % 1000},{i // 1000},0,0,0,0\n" for i in range(MARKS))
    flooder.sendall(marks.encode())
    with flooder.makefile("rb") as replies_seen:
        assert [replies_seen.readline() for _ in range(MARKS)][-1] == b"ok\n"
    sleeper = socket.create_connection(("127.0.0.1", proc.port), timeout=30)
    sleeper.sendall(b"where\n")
    assert sleeper.recv(100) == (HOME + "\n").encode()
    sleeper.sendall(b"sleep 30\nwhere\nmove 0 1\n")
    time.sleep(0.3)  # let the server read them
    start = time.monotonic()
    if how == "quit":
        quitter = socket.create_connection(("127.0.0.1", proc.port), timeout=30)
        quitter.sendall(b"where\nquit\nwhere\n")
        assert read_all(quitter) == [HOME, "ok", replies.SHUTTING_DOWN]
        quitter.close()
    else:
        proc.popen.send_signal(getattr(signal, how))
    assert proc.wait(timeout=120) == 0  # a hang guard: the sleeper's replies say it did not wait
    print(f"{how}: exited {time.monotonic() - start:.2f} s after, a tab never reading")
    assert read_all(sleeper) == [replies.SHUTTING_DOWN] * 3
    for sock in (sleeper, flooder, tab):
        sock.close()
    assert port_is_free(proc.port) and port_is_free(viewer_port)
    rest = proc.popen.stdout.read()
    assert "c2rviz: stopped" in rest and "Traceback" not in rest


@pytest.mark.parametrize("how", ["SIGTERM", "SIGINT", "quit"])
def test_a_stop_after_a_waiting_client_left_exits_0_with_the_recording_whole(
    c2rviz_process, tmp_path, capsys, how
):
    """Issue 23.1: client 1 records and moves; client 2 sleeps and closes its socket; a
    signal or `quit` then stops the program: status 0, no traceback, the recording whole."""
    from c2rviz.clients import player

    proc = c2rviz_process("--no-viewer", "--record-dir", str(tmp_path))
    recorder = socket.create_connection(("127.0.0.1", proc.port), timeout=60)
    stream = recorder.makefile("rb")

    def ask(line: str) -> str:
        recorder.sendall(line.encode() + b"\n")
        return stream.readline().decode().rstrip("\n")

    assert ask("record take").startswith("ok recording take")
    for q in ("0.1,0,0,0,0,0,0", "0.2,0.1,0,0,0,0,0", "0.3,0.2,0.1,0,0,0,0"):
        assert ask(f"joints {q}") == "ok"
    assert ask("mark") == "ok"
    sleeper = socket.create_connection(("127.0.0.1", proc.port), timeout=60)
    sleeper.sendall(b"sleep 100\n")
    time.sleep(0.2)  # let the server read it (no reply comes for 100 s)
    sleeper.close()
    if how == "quit":
        assert ask("quit") == "ok"
    else:
        proc.popen.send_signal(getattr(signal, how))
    status = proc.wait(60)
    log = "".join(proc.output) + proc.popen.stdout.read()
    assert status == 0 and "Traceback" not in log and "internal error" not in log, log
    stream.close()
    recorder.close()
    assert (tmp_path / "take.txt").is_file() and not list(tmp_path.glob(".take*")), log
    # c2rviz-play --check, in this process: the same main, without a second interpreter
    assert player.main(["--check", str(tmp_path / "take.txt")]) == 0, capsys.readouterr()
    rows = (tmp_path / "take.csv").read_text().splitlines()
    assert rows[-1].split(",")[1:4] == ["0.3", "0.2", "0.1"], rows[-3:]


def test_bye_then_an_immediate_close_costs_no_traceback(start_server, connect, caplog):
    """Issue 23.1: `bye` or `quit` followed at once by a closed socket is not an internal error."""
    server = start_server()
    for _ in range(20):
        sock = socket.create_connection((server.host, server.port), timeout=60)
        sock.sendall(b"bye\n")
        sock.close()
    client = connect(server)
    assert client.ask("where") == HOME
    assert "internal error" not in caplog.text and "Traceback" not in caplog.text
    assert not [r for r in caplog.records if r.levelname == "ERROR"]


def test_clients_over_the_limit_that_drop_at_once_cost_no_traceback(start_server, connect, caplog):
    """Issue 23.1: refusing clients over the limit while they connect and drop logs one
    warning each, never an exception."""
    server = start_server(max_clients=1)
    first = connect(server)
    for _ in range(200):
        sock = socket.create_connection((server.host, server.port), timeout=60)
        sock.close()
    assert first.ask("where") == HOME
    assert not [r for r in caplog.records if r.exc_info or r.levelname == "ERROR"], caplog.text
