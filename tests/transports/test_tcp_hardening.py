"""Bad input, overload and slow clients over real sockets.

The rule for every case: a clear ``error:`` reply (or a documented close), no
traceback, the shared state unchanged, a bystander connected throughout still
answered correctly, and the server still accepting new clients.
"""

from __future__ import annotations

import contextlib
import dataclasses
import http.client
import inspect
import logging
import math
import select
import socket
import struct
import threading
import time
import urllib.error
import urllib.request

import pytest
from support import ROOT

from c2rviz.app import cli, config
from c2rviz.errors import LineTooLong
from c2rviz.protocol import replies
from c2rviz.protocol.framing import BATCH_BYTES
from c2rviz.protocol.grammar import _MAX_INDEX_DIGITS
from c2rviz.transports import tcp_text as server_module
from c2rviz.transports.tcp_reading import LINGER_S, LOOK_AHEAD_BYTES, TURN_S
from c2rviz.transports.tcp_server import CommandServer
from c2rviz.view.door_rules import DoorPolicy

# A state away from home (so a stray home or joints shows) with long `where` replies.
START_Q = (0.123456789, -0.234567891, 0.345678912, -0.456789123, 0.567891234, -0.678912345, 0.0)
START = "joints " + ",".join(map(str, START_Q))
WHERE = replies.ok(replies.numbers(START_Q))
NAMES = "ok motoman_sia20d joint_s,joint_l,joint_e,joint_u,joint_r,joint_b,joint_t"


@pytest.fixture(autouse=True)
def no_tracebacks(caplog):
    """No test here may make the server (or asyncio under it) log an error or a traceback."""
    yield
    bad = [r for r in caplog.get_records("call") if r.levelno >= logging.ERROR or r.exc_info]
    assert bad == []


def state(server):
    """Everything a command could change: joints, markers, and what the scene was told."""
    world, scene = server.world, server.scene
    return server.call(
        lambda: (world.q, len(world.markers), len(scene.joints), len(scene.markers), scene.clears)
    )


def client_count(server):
    return server.call(lambda: len(server.server.connections))


def buffered(server) -> list[int]:
    """Bytes each connection holds of an unfinished line (call on the server's loop)."""
    return [len(c.framer.buffer) for c in server.server.connections]


def wait_for(predicate, timeout=60.0):
    deadline = time.monotonic() + timeout
    while not predicate():
        assert time.monotonic() < deadline, "timed out"
        time.sleep(0.01)


@pytest.fixture
def live(start_server, connect):
    """Factory: a server at START with a bystander client; returns (server, bystander, check).

    ``check()`` asserts the state is what it was, the bystander is answered, and a new
    client can still connect.
    """

    def start(**limits):
        server = start_server(**limits)
        bystander = connect(server)
        assert bystander.ask(START) == "ok"
        before = state(server)
        assert before[0] == pytest.approx(START_Q)

        def check():
            assert state(server) == before
            assert bystander.ask("where") == WHERE
            newcomer = connect(server)
            assert newcomer.ask("where") == WHERE
            newcomer.close()

        return server, bystander, check

    return start


# One bad line each; the connection stays open, so a `names` after it must be answered next.
BAD_LINES = [
    (b"\n", None, "empty-line"),
    (b"   \t  \n", None, "whitespace-only"),
    (b"\r\n", None, "bare-crlf"),
    (b"   # a comment\n", None, "comment-only"),
    (b"joints 1,2\n", "error: joints needs 7 values, got 2", "joints-too-few"),
    (b"joints 1,2,3,4,5,6,7,8\n", "error: joints needs 7 values, got 8", "joints-too-many"),
    (b"joints 0,0,0,0,0,0,nan\n", "error: joints: bad number 'nan'", "nan"),
    (b"move 0 NaN\n", "error: move: bad number 'NaN'", "NaN"),
    (b"move 0 inf\n", "error: move: bad number 'inf'", "inf"),
    (b"move 0 -Infinity\n", "error: move: bad number '-Infinity'", "-Infinity"),
    (b"move 0 1e309\n", "error: move: value '1e309' is not a finite number", "1e309"),
    (b"move 0 3.2\n", "error: joint_s (index 0) = 3.2 rad is outside its limits", "limit-rad"),
    (b"move 1 -1.92\n", "error: joint_l (index 1) = -1.92 rad is outside", "limit-rad-low"),
    (b"joints 0,0,0,0,0,0,4\n", "error: joint_t (index 6) = 4 rad is outside", "limit-joints"),
    (b"move 99 1\n", "error: joint index 99 out of range: motoman_sia20d has joints 0..6", "99"),
    (b"move -1 1\n", "error: move: bad joint index '-1'", "negative-index"),
    (b"move 0,1 90\n", "error: move: 2 indices but 1 values", "fewer-values"),
    (b"move 0,0 1,2\n", "error: move: joint 0 is given twice", "index-twice"),
    (b"move x 1\n", "error: move: bad joint index 'x'", "index-letter"),
    (b"move 1.5 1\n", "error: move: bad joint index '1.5'", "index-fraction"),
    ("move 0 \u0661\n".encode(), "error: character '\\u0661' at column 8", "arabic-digit"),
    ("move 0 \uff11\n".encode(), "error: character '\\uff11' at column 8", "fullwidth-digit"),
    (b"move 0 1_0\n", "error: move: bad number '1_0'", "underscore"),
    (b"move 0 0x10\n", "error: move: bad number '0x10'", "hex"),
    (b"move 0 1.5abc\n", "error: move: bad number '1.5abc'", "trailing-letters"),
    (b"joints 1,,2\n", "error: joints: empty value in list", "double-comma"),
    (b"joints 1,\n", "error: joints: empty value in list", "trailing-comma"),
    (b"move " + b"7" * 5000 + b" 1\n", "error: move: joint index '777777777777...'", "5000-digits"),
    (b"\xff\xfe\n", "error: " + replies.NOT_UTF8, "not-utf8"),
    (b"move 0 \xc3\n", "error: " + replies.NOT_UTF8, "truncated-utf8"),
    (b"home\x00x\n", "error: character '\\x00' at column 5", "nul-inside"),
    (b"home\x00\n", "error: character '\\x00' at column 5", "nul-at-end"),
    (b"jump 1\n", "error: unknown command 'jump' (try 'help')", "unknown-verb"),
    (b"mark 1,2,3\n", "error: mark: needs 6 values, got 3", "mark-count"),
    (b"mark 0,0,1,0,0,nan\n", "error: mark: bad number 'nan'", "mark-nan"),
    (b"color 1,1\n", "error: color: needs 3 values, got 2", "color-count"),
    (b"color 0,0,2\n", "error: color: channel 2 is outside 0..1", "color-range"),
    (b"rgb 0,0,256\n", "error: rgb: channel 256 is outside 0..255", "rgb-range"),
    (b"rgb -1,0,0\n", "error: rgb: channel -1 is outside 0..255", "rgb-negative"),
    (b"marker cone\n", "error: marker: unknown shape 'cone'", "marker-shape"),
    (b"sleep -1\n", "error: sleep: seconds must be >= 0, got -1", "sleep-negative"),
    (b"sleep nan\n", "error: sleep: bad number 'nan'", "sleep-nan"),
    (b"sleep 1e9\n", "error: sleep: 1e+09 s is over the limit of 3600 s", "sleep-too-long"),
]


@pytest.mark.parametrize(
    ("data", "expected"), [b[:2] for b in BAD_LINES], ids=[b[2] for b in BAD_LINES]
)
def test_a_bad_line_is_one_error_and_changes_nothing(live, connect, data, expected):
    server, _bystander, check = live()
    client = connect(server)
    client.send(data + b"names\n")
    if expected is not None:
        reply = client.read_line()
        assert reply.startswith(expected), reply
    assert client.read_line() == NAMES  # one reply per line: nothing more, nothing less
    check()


def test_limits_are_checked_in_degrees_too(live, connect):
    server, _bystander, check = live()
    client = connect(server)
    client.send("degrees\nmove 0 180.5\nmove 5 -109.5\njoints 0,0,0,0,0,0,181\nwhere\n")
    assert client.read_line() == "ok"
    assert client.read_line().startswith("error: joint_s (index 0) = 180.5 deg is outside")
    assert client.read_line().startswith("error: joint_b (index 5) = -109.5 deg is outside")
    assert client.read_line().startswith("error: joint_t (index 6) = 181 deg is outside")
    assert client.read_line() == replies.ok(replies.numbers(map(math.degrees, START_Q)))
    check()


@pytest.mark.parametrize(
    "line",
    [b"home\r\n", b"  HOME\t\n", b"\tHoMe   # back to zero\r\n"],
    ids=["crlf", "case", "tab"],
)
def test_case_whitespace_and_crlf_are_accepted(live, connect, line):
    server, bystander, _check = live()
    client = connect(server)
    client.send(line)
    assert client.read_line() == "ok"
    assert client.ask("where") == "ok 0,0,0,0,0,0,0"
    assert bystander.ask("where") == "ok 0,0,0,0,0,0,0"


def test_an_over_long_line_without_newline_is_refused_and_closed(live, connect):
    server, _bystander, check = live(max_line=1024)
    client = connect(server)
    held = [0]  # the most the server held for this client between reads
    sending = threading.Event()
    sending.set()

    def watch():
        while sending.is_set():
            sizes = server.call(lambda: buffered(server))
            held[0] = max(held[0], *sizes)

    client.send(b"x" * 1000)  # under the limit: held, waiting for its newline
    wait_for(lambda: max(server.call(lambda: buffered(server))))
    watcher = threading.Thread(target=watch)
    watcher.start()
    sent = 1000
    with contextlib.suppress(OSError):  # once the server stops reading and drops the rest
        for _ in range(20 * 1024):  # 20 MiB with no newline
            client.sock.sendall(b"x" * 1024)
            sent += 1024
    sending.clear()
    watcher.join()
    print(f"over-long line: {sent >> 20} MiB sent, the server held at most {held[0]} bytes")
    assert 1000 <= held[0] <= 1024
    assert client.read_line() == replies.error(LineTooLong(1024))
    assert client.closed_by_server()
    client.close()
    wait_for(lambda: client_count(server) == 1)
    check()


def test_the_line_limit_is_exact(live, connect):
    server, _bystander, check = live(max_line=128)
    ok_line = b"names" + b" " * 123  # 128 bytes, not counting the newline: allowed
    client = connect(server)
    client.send(ok_line + b"\n")
    assert client.read_line() == NAMES
    client.send(ok_line + b" \n")  # 129 bytes
    assert client.read_line() == replies.error(LineTooLong(128))
    assert client.closed_by_server()
    check()


@pytest.mark.parametrize(
    "chunks",
    [
        [b"x" * 500] * 4 + [b"quit\n"],
        [b"x" * 2000 + b"quit\n"],
        [b"x" * 2000 + b"\nquit\n"],
        [b"names\n" + b"x" * 2000 + b"\nquit\n"],
    ],
    ids=["chunks", "one-write", "newline-then-quit", "after-a-good-line"],
)
def test_nothing_after_an_over_long_line_runs(live, connect, chunks):
    server, _bystander, check = live(max_line=1024)
    client = connect(server)
    got = []
    for chunk in chunks:
        try:
            client.send(chunk)
        except OSError:
            break
        time.sleep(0.02)
    while line := client.read_line():
        got.append(line)
    answered = [NAMES] if chunks[0].startswith(b"names") else []
    assert got == [*answered, replies.error(LineTooLong(1024))]
    assert not server.quit.is_set()
    check()


@pytest.mark.parametrize("how", ["close", "shutdown-write"])
def test_a_last_line_without_its_newline_runs_at_eof(live, connect, how):
    """The client's FIN ends its last line (issue 23.11, as ``nc -q1`` expects): it runs and
    is answered, then the server closes; a client that closed outright runs it as well
    (a FIN is a FIN), and the reply it cannot take costs the server nothing."""
    server, bystander, _check = live()
    client = connect(server)
    client.send("joints 0,0,0,0,0,0,0.5")  # no newline: the FIN ends it
    wait_for(lambda: max(server.call(lambda: buffered(server))))
    if how == "close":
        client.close()
    else:
        client.sock.shutdown(socket.SHUT_WR)
        assert client.read_line() == "ok"
        assert client.closed_by_server()
    wait_for(lambda: client_count(server) == 1)
    assert bystander.ask("where") == "ok 0,0,0,0,0,0,0.5"
    newcomer = connect(server)
    assert newcomer.ask("where") == "ok 0,0,0,0,0,0,0.5"
    newcomer.close()


def test_a_reset_mid_line_ends_quietly(live, connect):
    server, _bystander, check = live()
    client = connect(server)
    client.send("move 0 0.5")
    wait_for(lambda: max(server.call(lambda: buffered(server))))
    client.sock.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
    client.close()  # RST, not FIN
    wait_for(lambda: client_count(server) == 1)
    check()  # and no_tracebacks checks the log


def test_a_reset_with_replies_pending_ends_quietly(live, connect):
    server, _bystander, check = live()
    client = connect(server)
    client.sock.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
    client.send(b"where\n" * 5000)
    client.close()
    wait_for(lambda: client_count(server) == 1)
    check()


@pytest.mark.parametrize(
    "request_bytes",
    [
        b"GET / HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n",
        b"POST /move HTTP/1.1\r\nHost: x\r\nContent-Length: 5\r\n\r\nquit\n",
        b"Host: 127.0.0.1:31000\r\nhome\r\n",
        b"post / HTTP/1.1\r\nhome\r\nquit\r\n",
        b"POST  /  HTTP/1.1\r\nhome\r\nquit\r\n",
        b"GET /\r\nX-Forwarded-For: 10.0.0.1\r\nhome\r\nquit\r\n",
    ],
    ids=["get", "post-with-quit-body", "header-first", "lowercase", "double-space", "http-0.9"],
)
def test_an_http_request_is_closed_at_its_first_line(live, connect, request_bytes):
    server, _bystander, check = live()
    client = connect(server)
    client.send(request_bytes)
    assert client.file.read() == replies.not_http(None)  # all of it, then the close
    assert not server.quit.is_set()
    check()


VIEWER_URL = "http://127.0.0.1:8080"


@pytest.mark.parametrize("method", ["GET", "POST", "HEAD"])
def test_a_real_http_client_is_told_where_the_viewer_is_and_nothing_runs(live, method):
    server, _bystander, check = live()
    server.call(setattr, server.server, "viewer_url", VIEWER_URL)  # as program.serve does
    conn = http.client.HTTPConnection(server.host, server.port, timeout=5)
    # One write: the request line, the headers and a body of commands that must not run.
    conn.request(method, "/", body=b"home\nquit\n")
    response = conn.getresponse()
    assert response.status == 400
    assert response.getheader("Content-Type") == "text/plain; charset=utf-8"
    assert response.getheader("Connection") == "close"
    body = response.read().decode()
    conn.close()
    if method != "HEAD":
        assert body == (
            "error: this is the c2rviz command port (one text command per line), not HTTP; "
            f"the viewer is at {VIEWER_URL}\n"
        )
    assert not server.quit.is_set()
    check()


def test_a_browser_url_on_the_command_port_gets_a_400_it_can_show(live):
    server, _bystander, check = live()
    with pytest.raises(urllib.error.HTTPError) as caught:
        urllib.request.urlopen(f"http://{server.host}:{server.port}/", timeout=5)
    assert caught.value.code == 400
    assert "c2rviz command port" in caught.value.read().decode()
    caught.value.close()
    check()


def test_one_client_over_the_maximum_is_told_and_closed(live, connect):
    server, bystander, check = live(max_clients=3)
    others = [connect(server), connect(server)]
    wait_for(lambda: client_count(server) == 3)
    extra = connect(server)
    extra.send("where\n" * 1000)  # talks at once: the refusal must still reach it
    assert extra.read_line() == replies.too_many_clients(3)
    assert extra.closed_by_server()
    for other in others:
        assert other.ask("where") == WHERE
    assert bystander.ask("where") == WHERE
    others[0].close()
    wait_for(lambda: client_count(server) == 2)
    check()  # a newcomer fits again


def test_a_client_that_never_reads_is_dropped_and_others_do_not_stall(live, connect):
    server, bystander, check = live(max_unread=64 * 1024)
    with socket.socket() as hog:
        hog.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)  # fill up fast
        hog.settimeout(30)
        hog.connect((server.host, server.port))
        wait_for(lambda: client_count(server) == 2)

        def flood():  # 100,000 lines and on: the kernel's buffers hold a few MB of replies
            with contextlib.suppress(OSError):  # reset once the server drops it
                for _ in range(1000):
                    hog.sendall(b"where\n" * 1000)  # replies never read

        flooder = threading.Thread(target=flood)
        flooder.start()
        round_trips = []
        while client_count(server) == 2 or len(round_trips) < 10:  # while the hog is served
            start = time.perf_counter()
            assert bystander.ask("where") == WHERE
            round_trips.append(time.perf_counter() - start)
        flooder.join(timeout=30)
        ran = server.call(lambda: len(server.scene.commands)) - len(round_trips)
        print(
            f"hog dropped after the server ran {ran} of its lines; bystander: "
            f"{len(round_trips)} round trips meanwhile, slowest {max(round_trips) * 1e3:.1f} ms"
        )
        assert not flooder.is_alive()
        with contextlib.suppress(OSError):  # whatever replies got through, then EOF or reset
            while hog.recv(65536):
                pass
    check()


def test_a_line_left_unfinished_is_closed_after_the_timeout(live, connect):
    server, _bystander, check = live(partial_timeout_s=0.3)
    client = connect(server)
    client.send("move 0 0.5")
    assert client.read_line() == replies.incomplete_line(0.3)
    assert client.closed_by_server()
    check()


def test_an_idle_client_between_lines_is_not_dropped(live, connect):
    server, _bystander, check = live(partial_timeout_s=0.2)
    client = connect(server)
    assert client.ask("where") == WHERE
    time.sleep(0.5)
    assert client.ask("where") == WHERE
    check()


def test_a_steady_stream_split_across_reads_is_not_dropped(live, connect):
    """Each line finishes in time, but some line is always unfinished at a read's end."""
    server, _bystander, check = live(partial_timeout_s=1.0)  # each step: 10x slack
    client = connect(server)
    client.send("wh")
    for _ in range(20):  # 20 x 0.1 s: well past the timeout in total
        time.sleep(0.1)
        client.send("ere\nwh")
        assert client.read_line() == WHERE
    client.send("ere\n")
    assert client.read_line() == WHERE
    check()


@pytest.mark.wall_clock
def test_a_sleep_does_not_count_against_the_partial_timeout(live, connect):
    """While a client sleeps the server is not reading it: its line cannot finish."""
    server, _bystander, check = live(partial_timeout_s=1.0)  # each step: 10x slack
    client = connect(server)
    client.send("wh")
    time.sleep(0.1)
    client.send("ere\nsleep 2\nwh")
    assert client.read_line() == WHERE
    time.sleep(0.1)
    client.send("ere\n")
    assert client.read_line() == "ok"  # the sleep
    assert client.read_line() == WHERE
    check()


@pytest.mark.wall_clock
def test_thousands_of_lines_in_one_write_are_all_answered_in_order(live, connect):
    """A big read runs in batches (other clients get turns in between); nothing is lost."""
    server, bystander, check = live()
    lines = ["where"] * 5000
    lines[1500] = "sleep 0"  # a pause inside the first batch ...
    lines[3000] = "sleep 0.01"  # ... and one in a later batch
    lines[4000] = "jump"
    client = connect(server)
    client.send("".join(line + "\n" for line in lines))
    client.sock.shutdown(socket.SHUT_WR)  # end of input: the server must still answer it all
    got = []
    while reply := client.read_line():
        got.append(reply)
    expected = [WHERE] * 5000
    expected[1500] = expected[3000] = "ok"
    expected[4000] = "error: unknown command 'jump' (try 'help')"
    assert got == expected
    check()


def test_a_long_batch_gives_way_to_another_client_after_its_time_slice(live, connect, monkeypatch):
    """A batch of lines stops after ``TURN_S`` of work (here: at once) and lets the other
    clients in: a `where` that arrived just after it sees the arm partway through it."""
    server, _bystander, _check = live()
    monkeypatch.setattr(server_module, "TURN_S", 0.0)
    flooder, reader = connect(server), connect(server)
    assert reader.ask("where") == WHERE  # both connections are set up on the server
    steps = [f"move 0 {1 + k / 500:.3f}" for k in range(1, 501)]  # 1.002 .. 2 rad
    assert len("".join(line + "\n" for line in steps)) < BATCH_BYTES  # one batch
    hold, held = threading.Event(), threading.Event()

    def block() -> None:  # the loop waits here while the lines arrive, in a known order
        held.set()
        hold.wait(timeout=60)

    def arrived(client) -> None:
        """Wait until the server's end of ``client``'s socket has data to read."""
        host, port = client.sock.getsockname()[:2]
        local = f"{host}:{port}"
        (mine,) = [c for c in server.server.connections if c.peer == local]
        fd = mine.transport.get_extra_info("socket").fileno()
        assert select.select([fd], [], [], 60)[0], "the lines did not arrive"

    server.loop.call_soon_threadsafe(block)
    assert held.wait(timeout=60)
    flooder.send("".join(line + "\n" for line in steps))
    arrived(flooder)  # epoll reports ready sockets first come, first served
    reader.send("where\n")
    arrived(reader)
    hold.set()
    seen = float(reader.read_line().removeprefix("ok ").split(",")[0])
    assert [flooder.read_line() for _ in steps] == ["ok"] * len(steps)
    assert 1.0 < seen < 2.0  # after the flood began, before it ended
    assert server.q[0] == 2.0


def test_a_quit_after_thousands_of_lines_answers_the_rest_with_shutting_down(live, connect):
    server, _bystander, _check = live()
    client = connect(server)
    client.send("where\n" * 3000 + "quit\n" + "where\n" * 2000 + "\n# no reply\n")
    got = []
    while reply := client.read_line():
        got.append(reply)
    assert got == [WHERE] * 3000 + ["ok"] + [replies.SHUTTING_DOWN] * 2000
    assert server.quit.wait(timeout=60)


def test_the_limits_table_matches_the_code():
    """docs/limits.md: every default, flag, ini key and range is the one the code uses."""
    text = (ROOT / "docs" / "limits.md").read_text()
    table = text.split("| Past the limit |")[1].split("\n\n")[0]
    rows = [[c.strip() for c in row.strip("|").split("|")] for row in table.splitlines()[2:]]
    flags = {a.option_strings[0]: a.dest for a in cli.build_parser()._actions if a.option_strings}
    defaults = {f.name: f.default for f in dataclasses.fields(config.ServerLimits)}
    seen = set()
    for _limit, default, flag, key, allowed, _past in rows:
        field, kind, low, high = config._OPTIONS[key.strip("`")]
        assert flags[flag.strip("`")] == field
        assert kind(default.split()[0]) == defaults[field]
        assert [float(v) for v in allowed.split("..")] == [low, high]
        seen.add(field)
    assert seen == set(defaults)  # every limit is in the table
    assert f"| {BATCH_BYTES} | `protocol.framing.BATCH_BYTES` |" in text
    assert f"| {LOOK_AHEAD_BYTES} | `transports.tcp_reading.LOOK_AHEAD_BYTES` |" in text
    assert f"| {TURN_S * 1000:g} ms | `transports.tcp_reading.TURN_S` |" in text
    assert f"| {LINGER_S:g} s | `transports.tcp_reading.LINGER_S` |" in text
    assert f"| {_MAX_INDEX_DIGITS} | `protocol.grammar._MAX_INDEX_DIGITS` |" in text
    grace = inspect.signature(CommandServer.stop).parameters["grace_s"].default
    assert f"| {grace:g} s | `CommandServer.stop(grace_s)` |" in text
    assert "| Command server | `127.0.0.1` | `--host` | `host` |" in text
    assert config.Settings().host == config.Settings().viewer_host == "127.0.0.1"


def test_the_viewer_limits_in_the_docs_match_the_code():
    """docs/limits.md: the viewer's limits and settings are the ones the code uses."""
    text = (ROOT / "docs" / "limits.md").read_text()
    table = text.split("| When refused |")[1].split("\n\n")[0]
    rows = [[c.strip() for c in row.strip("|").split("|")] for row in table.splitlines()[2:]]
    flags = {a.option_strings[0]: a.dest for a in cli.build_parser()._actions if a.option_strings}
    settings = config.Settings()
    assert rows
    for _limit, default, flag, key, allowed, past in rows:
        field, kind, low, high = config._OPTIONS[key.strip("`")]
        assert flags[flag.strip("`")] == field
        assert kind(default) == getattr(settings, field)
        assert [float(v) for v in allowed.split("..")] == [low, high]
        assert f"{default} tabs open" in past
    assert settings.max_viewers == DoorPolicy().max_clients  # the door's own default
    policy = DoorPolicy()
    assert f"| {policy.max_frame_bytes} | `DoorPolicy.max_frame_bytes` |" in text
    assert f"| {policy.max_queued_frames} | `DoorPolicy.max_queued_frames` |" in text
    from c2rviz.view.viser_scene import STOP_TIMEOUT_S

    assert f"| {STOP_TIMEOUT_S:g} s | `viser_scene.STOP_TIMEOUT_S` |" in text
    for flag, key in (("--viewer-origin", "viewer_origins"), ("--viewer-token", "viewer_token")):
        assert flags[flag] == key
        assert f"`{flag}`" in text and f"`{key}`" in text
        assert key in config._TEXT_OPTIONS
