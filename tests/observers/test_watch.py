"""The `watch` stream through the real server: state and event lines between the replies,
at most HZ states a second (judged from the T in the lines), the latest state for a slow
reader, and never a cost to the other clients or the server's memory."""

from __future__ import annotations

import math
import re
import socket
import subprocess
import threading

import numpy as np
import pytest
from support import CTRL_C_ABLE, ROOT, Client, ServerThread
from watch_support import EVENT, STATE, ask, read_until, states

from c2rviz.observers.watch import STREAM_ALLOWANCE_BYTES, NotAConnection
from c2rviz.protocol import replies
from c2rviz.session.session import Session

FAR = "90,45,0,-30,0,60,0"  # degrees, motoman_sia20d


@pytest.mark.wall_clock
def test_a_fast_mover_is_streamed_at_most_hz_times_a_second(server: ServerThread, connect):
    mover, watcher = connect(server), connect(server)
    for line in ("degrees", "motion on", "speed 100"):
        assert mover.ask(line) == "ok"
    assert watcher.ask("degrees") == "ok"
    assert watcher.ask("watch 20") == "ok"  # the reply first, then the stream
    seen: list[str] = []
    read_until(watcher, lambda line: line.startswith("state"), seen)
    assert mover.ask(f"j {FAR}") == "ok"  # on arrival
    read_until(watcher, lambda line: line == "event arrived", seen)
    where = ask(watcher, "where", seen)
    got = states(seen)
    assert len(got) >= 5, seen  # the move takes over a second at full speed
    assert all(len(values) == 7 for _, values in got)
    times = np.array([t for t, _ in got])
    assert (np.diff(times) >= 1 / 20 - 1e-6).all(), np.diff(times)  # at most 20 a second
    # The last state is where the arm is, exactly as `where` says it.
    last = [line for line in seen if line.startswith("state")][-1]
    assert last.split(" ", 2)[2] == where.removeprefix("ok ") == FAR
    assert seen.index("event arrived") > seen.index(last)
    # Between the start and the end the arm was seen on the way, each joint monotone.
    values = np.array([v for _, v in got])
    moved = np.array([float(v) for v in FAR.split(",")]) != 0
    steps = np.diff(values[:, moved], axis=0) * np.sign(values[-1, moved])
    assert (steps >= -1e-9).all()
    assert ((values[1:-1, moved] != 0) & (values[1:-1, moved] != values[-1, moved])).any()


@pytest.mark.wall_clock
def test_state_times_count_from_the_server_start_and_rise(server: ServerThread, connect):
    watcher, mover = connect(server), connect(server)
    assert watcher.ask("watch 1000") == "ok"
    for k in range(50):
        assert mover.ask(f"move 0 {0.01 * k}") == "ok"
    seen: list[str] = []
    read_until(watcher, lambda line: line.endswith(f" {replies.numbers([0.49])},0,0,0,0,0,0"), seen)
    times = [t for t, _ in states(seen)]
    assert times == sorted(set(times))
    now = server.call(lambda: server.world.clock.now() - server.services.watch.origin)
    assert 0 <= times[0] <= times[-1] <= now


@pytest.mark.wall_clock
def test_events_marker_clear_stopped(server: ServerThread, connect):
    watcher, other = connect(server), connect(server)
    assert watcher.ask("degrees") == "ok"
    assert watcher.ask("watch") == "ok"
    seen: list[str] = []
    for line in ("degrees", "color 0,0.5,1", "marker cube", "mark 0.5,0.25,1,10,30,45"):
        assert other.ask(line) == "ok"
    read_until(watcher, lambda line: line.startswith("event marker"), seen)
    assert seen[-1] == "event marker 0.5,0.25,1,10,30,45 cube 0,0.5,1"
    assert other.ask("clear") == "ok"
    read_until(watcher, lambda line: line == "event clear", seen)
    for line in ("motion follow", "speed 20", f"j {FAR}"):
        assert other.ask(line) == "ok"
    read_until(
        watcher, lambda line: line.startswith("state") and line.split()[2] != "0,0,0,0,0,0,0", seen
    )
    assert other.ask("stop") == "ok"  # at rest
    read_until(watcher, lambda line: line.startswith("event"), seen)
    assert seen[-1] == "event stopped"
    rest = ask(watcher, "where", seen)
    assert [line for line in seen if line.startswith("state")][-1].split()[2] == rest[3:]
    assert rest != f"ok {FAR}"  # it stopped short


@pytest.mark.wall_clock
def test_a_movel_in_motion_ends_with_event_arrived(server: ServerThread, connect):
    watcher, mover = connect(server), connect(server)
    assert mover.ask("j 0.1,0.4,0,-0.6,0,0.7,0") == "ok"
    x, y, z, *rpy = (float(v) for v in mover.ask("pose")[3:].split(","))
    assert watcher.ask("watch") == "ok"
    seen: list[str] = []
    for line in ("motion on", "lspeed 0.5"):
        assert mover.ask(line) == "ok"
    goal = ",".join(map(str, [x, y + 0.1, z, *rpy]))
    assert mover.ask(f"movel {goal}") == "ok"  # on arrival
    read_until(watcher, lambda line: line.startswith("event"), seen)
    assert seen[-1] == "event arrived"


@pytest.mark.wall_clock
def test_collisions_are_events_when_they_begin_and_end(server: ServerThread, connect):
    watcher, other = connect(server), connect(server)
    assert watcher.ask("watch") == "ok"
    seen: list[str] = []
    # A box in front of the arm; folding the arm forward puts its wrist in the box.
    assert other.ask("object table box 0.4,0.4,0.1 0.6,0,0.9,0,0,0") == "ok"
    assert other.ask("degrees") == "ok"
    assert other.ask("j 0,60,0,60,0,0,0") == "ok"
    read_until(watcher, lambda line: line.startswith("event collision"), seen)
    pairs = seen[-1].removeprefix("event collision ")
    assert pairs != "none" and all(pair.endswith("~table") for pair in pairs.split(","))
    assert other.ask("collisions") == f"ok {pairs}"
    assert other.ask("home") == "ok"
    read_until(watcher, lambda line: line.startswith("event collision"), seen)
    assert seen[-1] == "event collision none"
    assert all(EVENT.fullmatch(line) for line in seen if line.startswith("event"))


def test_unwatch_ends_the_stream_and_watch_again_restarts_it(server: ServerThread, connect):
    watcher, other = connect(server), connect(server)
    assert watcher.ask("watch") == "ok"
    assert watcher.read_line().startswith("state ")
    assert ask(watcher, "unwatch") == "ok"
    for k in range(20):
        assert other.ask(f"move 0 {0.01 * k}") == "ok"
        assert other.ask("mark") == "ok"
    assert watcher.ask("where") == "ok 0.19,0,0,0,0,0,0"  # no stream line came before it
    assert watcher.ask("unwatch") == "ok"  # not watching: still fine
    assert watcher.ask("watch 5") == "ok"
    assert watcher.read_line().endswith(" 0.19,0,0,0,0,0,0")  # the state now, at once


def test_bad_hz_is_refused_and_the_stream_does_not_start(server: ServerThread, connect):
    client = connect(server)
    assert client.ask("watch 0") == (
        "error: watch: HZ must be above 0 and at most 1000, got 0 (usage: watch [HZ])"
    )
    assert client.ask("watch -1").startswith("error: watch: HZ must be above 0")
    assert client.ask("watch 1e9").startswith("error: watch: HZ must be above 0")
    assert client.ask("rand") == "ok"
    assert client.ask("home") == "ok"
    assert client.ask("where") == "ok 0,0,0,0,0,0,0"  # no state line in between


def test_the_page_has_no_stream_of_its_own(server: ServerThread):
    def watch_from_the_page() -> None:
        server.services.watch.watch(Session(server.services, "page"), None)

    with pytest.raises(NotAConnection, match="page has no stream of its own"):
        server.call(watch_from_the_page)


def _rss_mb() -> float:
    with open("/proc/self/status") as status:
        return int(re.search(r"VmRSS:\s+(\d+)", status.read()).group(1)) / 1024  # type: ignore[union-attr]


@pytest.mark.wall_clock
def test_a_watcher_that_never_reads_costs_nothing(server: ServerThread, connect):
    """A long flood of moves and markers while a watcher reads nothing: the
    flooder's replies all come, the server holds at most a small buffer for the watcher
    (it is never dropped), and when it reads it finds the latest state."""
    sock = socket.socket()
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)  # its kernel buffers fill soon
    sock.connect((server.host, server.port))
    watcher = Client.__new__(Client)
    watcher.sock, watcher.file = sock, sock.makefile("rb")
    try:
        _flood_past(server, connect(server), watcher)
    finally:
        watcher.close()


def _flood_past(server: ServerThread, flooder: Client, watcher: Client) -> None:
    assert watcher.ask("watch 1000") == "ok"
    assert flooder.ask("where") == "ok 0,0,0,0,0,0,0"

    def stream_state() -> tuple[int, bool]:
        hub = server.services.watch
        (connection,) = [c for c in server.server.connections if hub.streams[c.session].active]
        assert connection.transport is not None
        return connection.transport.get_write_buffer_size(), connection.stream.paused

    def payload(round_: int) -> list[str]:  # every move of the flood is a new state
        lines = []
        for k in range(2000 * round_, 2000 * (round_ + 1)):
            lines.append(f"move 0,1 {math.sin(k / 300):.6f},{0.9 * (math.cos(k / 300) - 1):.6f}\n")
            lines.append("mark\n")
        return lines

    start_rss = _rss_mb()
    paused_at: int | None = None
    sent = rounds = 0
    # A long flood, judged by its work, not the wall: on until the watcher's stream has
    # paused, then 10 rounds more (40,000 lines) with the stream held.
    while paused_at is None or rounds < paused_at + 10:
        lines = payload(rounds)
        answers: list[str] = []
        reader = threading.Thread(target=_read_lines, args=(flooder, len(lines), answers))
        reader.start()
        flooder.send("".join(lines))
        reader.join(timeout=60)
        assert answers == ["ok"] * len(lines)  # the flooder's replies are unaffected
        sent += len(lines)
        rounds += 1
        buffered, now_paused = server.call(stream_state)
        assert buffered <= STREAM_ALLOWANCE_BYTES
        if now_paused and paused_at is None:
            paused_at = rounds  # the watcher's stream had to wait
        assert rounds < 500, "the watcher's stream never had to wait"
    assert _rss_mb() - start_rss < 100  # generous: the stream holds one state and 256 events
    final = flooder.ask("where")
    seen: list[str] = []
    watcher.sock.settimeout(30)
    read_until(
        watcher, lambda line: line.startswith("state") and line.split()[2] == final[3:], seen
    )
    dropped = [int(line.split()[2]) for line in seen if line.startswith("event dropped")]
    assert sum(dropped) > 0  # the events it could not take were counted
    assert len(seen) < sent  # it skipped states rather than getting them all
    assert ask(watcher, "where") == final  # and it is still connected


def _read_lines(client: Client, count: int, into: list[str]) -> None:
    into.extend(client.read_line() for _ in range(count))


@pytest.mark.wall_clock
def test_cli_watch_prints_the_stream_until_ctrl_c(server: ServerThread, connect):
    proc = subprocess.Popen(
        [*CTRL_C_ABLE, "-m", "c2rviz.clients.repl", "--watch", "50", "--port", str(server.port)],
        cwd=ROOT,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert proc.stdout is not None
        first = proc.stdout.readline()
        assert STATE.fullmatch(first.rstrip("\n")), first
        mover = connect(server)
        assert mover.ask("move 0 0.5") == "ok"
        assert mover.ask("mark") == "ok"
        got = [proc.stdout.readline().rstrip("\n") for _ in range(2)]
        assert got[0] == "state " + got[0].split()[1] + " 0.5,0,0,0,0,0,0"
        assert got[1].startswith("event marker ")
        proc.send_signal(2)  # Ctrl-C
        assert proc.wait(timeout=30) == 0
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
        proc.stdout.close()  # type: ignore[union-attr]
        proc.stderr.close()  # type: ignore[union-attr]


@pytest.mark.wall_clock
def test_repl_watch_prints_the_stream_until_ctrl_c_then_goes_on(server: ServerThread, connect):
    proc = subprocess.Popen(
        [*CTRL_C_ABLE, "-m", "c2rviz.clients.repl", "--port", str(server.port)],
        cwd=ROOT,
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert proc.stdin is not None and proc.stdout is not None
        proc.stdin.write("degrees\nwatch 10\n")
        proc.stdin.flush()
        assert proc.stdout.readline() == "ok\n"  # degrees
        first = proc.stdout.readline().rstrip("\n")
        assert first.endswith(" 0,0,0,0,0,0,0") and STATE.fullmatch(first), first
        assert connect(server).ask("move 1 0.5") == "ok"  # radians, from another client
        moved = proc.stdout.readline().rstrip("\n")
        assert moved.endswith(f" 0,{replies.numbers([math.degrees(0.5)])},0,0,0,0,0"), moved
        proc.send_signal(2)  # Ctrl-C ends the watch, not the REPL
        proc.stdin.write("move 1 0\nwhere\n")
        proc.stdin.close()
        rest = proc.stdout.read()
        assert proc.wait(timeout=30) == 0
        assert rest.splitlines()[0] == "ok"  # no stream line after the watch ended
        assert rest.splitlines()[1] == "ok 0,0,0,0,0,0,0"  # piped: `where` is the server's reply
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
        for stream in (proc.stdin, proc.stdout, proc.stderr):
            if stream is not None and not stream.closed:
                stream.close()
