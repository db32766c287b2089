"""The REPL and the player against a real server.

``main(argv)`` runs in-process where that keeps the test fast; a subprocess
(pipes, or a pseudo-terminal from ``os.openpty``: no pexpect needed) where the
real process matters: prompts, Ctrl-C/Ctrl-D, exit statuses, retrying.
"""

from __future__ import annotations

import io
import math
import os
import re
import select
import signal
import socket
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path
from types import SimpleNamespace

import pytest
from support import ROOT

from c2rviz.clients import connection as dialing
from c2rviz.clients import player, repl
from c2rviz.clients.client import Client
from c2rviz.clients.connection import ServerUnavailable, default_address, server_address
from c2rviz.clients.goto import motion_of
from c2rviz.errors import C2rvizError, ConfigError
from c2rviz.protocol import registry

MOTOMAN = str(ROOT / "commands" / "motoman.txt")
REPL_SCRIPT = str(ROOT / "clients" / "socketcmdline.py")
PLAYER_SCRIPT = str(ROOT / "clients" / "fileplayer.py")
SEED_END = "ok -90,-90,0,0,0,0,0"


def free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


def where_degrees(server, connect) -> str:
    """``where`` in degrees, from a separate client."""
    other = connect(server)
    assert other.ask("degrees") == "ok"
    return other.ask("where")


def write(tmp_path: Path, name: str, text: str) -> str:
    path = tmp_path / name
    path.write_text(text)
    return str(path)


def run_repl(monkeypatch, text: str, *args: str) -> int:
    """``repl.main`` with ``text`` as piped stdin."""
    monkeypatch.setattr(sys, "stdin", io.StringIO(text))
    return repl.main(list(args))


def env() -> dict[str, str]:
    """A client process's environment: this tree's c2rviz, not the one installed."""
    return {**os.environ, "PYTHONUNBUFFERED": "1", "TERM": "dumb", "PYTHONPATH": str(ROOT)}


def joints_lines(server) -> list[str]:
    """The ``joints`` lines the server has accepted, from every client."""
    return [line for line in server.scene.commands if line.split()[0] in ("joints", "j")]


@pytest.fixture
def old_server(server, monkeypatch):
    """The real server as it was before motion: ``motion`` is not one of its verbs.

    It answers ``motion`` with ``error: unknown command 'motion' (try 'help')``, as
    those servers did, because the verb is taken out of the real registry for the
    test (the server runs in this process); everything else is the real server.
    """
    monkeypatch.delitem(registry.LOOKUP, "motion")
    return server


# --- the shared client -------------------------------------------------------------------


def test_clients_do_not_import_pinocchio():
    code = (
        "import sys, c2rviz.clients.client, c2rviz.clients.repl, c2rviz.clients.player\n"
        "print(c2rviz.clients.connection.default_address())\n"
        "print(sorted(m for m in ('pinocchio', 'viser', 'numpy') if m in sys.modules))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.splitlines() == ["('127.0.0.1', 31000)", "[]"]


def test_default_address_reads_the_ini(tmp_path):
    ini = write(tmp_path, "my.ini", "[options]\nhost = 0.0.0.0\nport = 31234\n")
    assert default_address(ini) == ("127.0.0.1", 31234)


def test_flags_win_and_the_ini_fills_in_the_rest(tmp_path):
    ini = write(tmp_path, "my.ini", "[options]\nhost = 10.1.2.3\nport = 31234\n")
    assert server_address(None, None, ini) == ("10.1.2.3", 31234)
    assert server_address("h", None, ini) == ("h", 31234)
    assert server_address(None, 0, ini) == ("10.1.2.3", 0)  # 0 is a port, not "not given"
    assert server_address("h", 5, tmp_path / "nonesuch.ini") == ("h", 5)  # ini not needed
    with pytest.raises(ConfigError, match="does not exist"):
        server_address("h", None, tmp_path / "nonesuch.ini")


def test_client_tracks_units_and_restores_them_after_a_reconnect(server, connect):
    client = Client(server.host, server.port)
    assert client.ask("degrees") == "ok"
    assert client.in_degrees
    client.close()
    assert client.ask("move 0 90") == "ok"  # reconnected, still in degrees
    assert math.isclose(server.q[0], math.pi / 2)
    assert client.ask("RADIANS # back") == "ok"
    assert not client.in_degrees
    client.close()


def test_client_gives_up_after_its_retry_time(monkeypatch):
    """Not at once (it waited its 0.3 s), and not later: its pauses never reach past the
    retry time (judged on what it asked to sleep, not on how long a busy machine took)."""
    port = free_port()
    notes: list[str] = []
    pauses: list[float] = []

    def sleep(seconds: float) -> None:
        pauses.append(seconds)
        time.sleep(seconds)

    monkeypatch.setattr(dialing, "time", SimpleNamespace(monotonic=time.monotonic, sleep=sleep))
    client = Client("127.0.0.1", port, retry_s=0.3, notify=notes.append)
    with pytest.raises(ServerUnavailable, match=f"no c2rviz server at 127.0.0.1:{port}") as caught:
        client.open()
    assert caught.value.waited_s >= 0.3  # gave up, and not at once
    assert 0 < pauses[0] <= 0.05  # a delay that grows (doubling, cut at the deadline)...
    assert all(b <= 2 * a + 1e-12 for a, b in zip(pauses, pauses[1:]))
    assert 0 < sum(pauses) <= 0.3 + 1e-9  # ...and none past the deadline
    assert len(notes) == 1 and "retrying" in notes[0]


def test_client_motion_reads_a_real_servers_reply(server, monkeypatch):
    client = Client(server.host, server.port)
    assert client.motion() == "off"
    assert client.ask("motion follow") == "ok"
    assert client.motion() == "follow"
    monkeypatch.delitem(registry.LOOKUP, "motion")  # the same server, as before motion
    reply = client.ask("motion")
    assert reply == "error: unknown command 'motion' (try 'help')"
    assert motion_of(reply) is None
    for odd in ("ok sideways", "error: motion: unknown mode 'x'", "ok"):
        with pytest.raises(C2rvizError, match="unexpected reply to 'motion'"):
            motion_of(odd)
    client.close()


@pytest.fixture
def cell():
    """A real server with two robots, ``left`` (motoman) and ``right`` (kuka_lwr)."""
    from support import ServerThread, load_robot

    from c2rviz.app.config import ServerLimits

    robots = {"left": load_robot("motoman_sia20d"), "right": load_robot("kuka_lwr")}
    # The wall clock (clock=None): its REPL tests race a move with Ctrl-C.
    server = ServerThread(robots, ServerLimits(), clock=None).start()  # type: ignore[arg-type]
    yield server
    server.stop()


def test_client_restores_its_robot_after_a_reconnect(cell):
    client = Client(cell.host, cell.port)
    assert client.joint_names()[0] == "joint_s" and client.robot_name == "left"
    assert client.ask("robot right") == "ok"
    assert client.chosen_robot == "right"
    assert client.joint_names()[0] == "lwr_0_joint" and client.robot_name == "right"  # asked again
    client.close()
    assert client.ask("robot") == "ok right"  # a new connection, the same robot
    client.close()


# --- the player ----------------------------------------------------------------------------


def test_player_plays_motoman_txt_to_the_seed_end_pose(server, connect, capsys):
    assert player.main([MOTOMAN, "--port", str(server.port), "--speed", "1000"]) == 0
    sleeps = [line for line in server.scene.commands if line.startswith("sleep")]
    assert sleeps == [f"sleep {s / 1000!r}" for s in (5, 5, 3, 3, 3, 3, 4)]  # 26 s / 1000
    assert where_degrees(server, connect) == SEED_END
    out = capsys.readouterr().out
    assert "[ 1/16] sleep 5 -> ok" in out
    assert "[16/16] move 0,1 -90,-90 -> ok" in out
    assert "16 commands, all ok" in out
    assert "\r" not in out  # plain lines when not on a terminal


def test_player_quiet_prints_errors_and_the_summary_only(server, tmp_path, capsys):
    assert player.main([MOTOMAN, "--port", str(server.port), "--speed", "1e4", "--quiet"]) == 0
    captured = capsys.readouterr()
    assert captured.out.startswith(f"{MOTOMAN}: 16 commands, all ok, in ")
    assert captured.out.count("\n") == 1 and captured.err == ""
    limit = write(tmp_path, "limit.txt", LIMIT_LINE_3)
    assert player.main([limit, "--port", str(server.port), "-q", "--keep-going"]) == 1
    captured = capsys.readouterr()
    assert captured.out == ""
    first, summary = captured.err.splitlines()
    assert first.startswith(f"{limit}:3: error: joint_l (index 1) = 500 deg is outside")
    assert summary == f"{limit}: 1 error (4 commands)"


BAD_LINE_3 = "degrees\nmove 0 30\nmvoe 1 30   # typo\nhome\n"


def test_check_reports_a_bad_line_without_connecting(tmp_path, capsys):
    bad = write(tmp_path, "bad.txt", BAD_LINE_3)
    port = free_port()  # nothing listens there: --check must not connect
    assert player.main([bad, "--check", "--port", str(port)]) == 2
    err = capsys.readouterr().err
    assert f"{bad}:3: error: unknown command 'mvoe'" in err
    assert "nothing was sent" in err
    good = player.main([MOTOMAN, "--check", "--port", str(port)])
    assert good == 0
    assert "16 commands, all parse" in capsys.readouterr().out


def test_a_bad_line_3_is_rejected_before_anything_moves(server, connect, tmp_path, capsys):
    other = connect(server)
    assert other.ask("move 2 0.5") == "ok"
    before = server.q
    bad = write(tmp_path, "bad.txt", BAD_LINE_3)
    assert player.main([bad, "--port", str(server.port)]) == 2
    assert f"{bad}:3: error: unknown command" in capsys.readouterr().err
    assert server.q == before
    assert other.ask("where") == "ok 0,0,0.5,0,0,0,0"


def test_joint_counts_and_indices_are_checked_against_the_robot(server, tmp_path, capsys):
    before = server.q
    text = "degrees\nmove 0 10\njoints 1,2,3\nmove 1,9 1,2\n"
    path = write(tmp_path, "count.txt", text)
    assert player.main([path, "--port", str(server.port)]) == 2
    err = capsys.readouterr().err
    assert f"{path}:3: error: joints needs 7 values, got 3" in err
    assert f"{path}:4: error: joint index 9 out of range: motoman_sia20d has joints 0..6" in err
    assert server.q == before


def test_the_robot_header_is_read_from_the_opening_comments(tmp_path):
    path = Path(write(tmp_path, "a.txt", "# a demo\n#Robot:  kuka_lwr  \nhome\n# robot: x\n"))
    assert player.load_script(path).robot == "kuka_lwr"
    late = Path(write(tmp_path, "b.txt", "home\n# robot: kuka_lwr\n"))
    assert player.load_script(late).robot is None  # after the first command: a comment
    prose = Path(write(tmp_path, "c.txt", "# robot: run it with c2rviz --robot x\nhome\n"))
    assert player.load_script(prose).robot is None  # one word only
    for path in sorted((ROOT / "commands").glob("*.txt")):
        assert player.load_script(path).robot is not None, path.name


KUKA = str(ROOT / "commands" / "kuka_lwr.txt")


def test_a_file_for_another_robot_is_warned_about(server, capsys):
    assert player.main([KUKA, "--port", str(server.port), "--speed", "1000"]) == 0
    captured = capsys.readouterr()
    assert (
        f"warning: {KUKA} is written for robot kuka_lwr (its '# robot:' line), "
        "but the server runs motoman_sia20d (7 joints); playing it anyway" in captured.err
    )
    assert "all ok" in captured.out
    assert player.main([MOTOMAN, "--port", str(server.port), "--speed", "1000"]) == 0
    assert "warning" not in capsys.readouterr().err  # motoman.txt says motoman_sia20d


@pytest.mark.wall_clock
def test_strict_refuses_a_file_for_another_robot(server, connect, capsys):
    other = connect(server)
    assert other.ask("move 2 0.5") == "ok"
    before = server.q
    assert player.main([KUKA, "--port", str(server.port), "--strict"]) == 2
    err = capsys.readouterr().err
    assert "written for robot kuka_lwr" in err and "the server runs motoman_sia20d" in err
    assert "nothing was sent" in err
    assert server.q == before
    assert player.main([MOTOMAN, "--port", str(server.port), "--speed", "1e4", "--strict"]) == 0


def test_repl_file_warns_about_another_robot(server, monkeypatch, capsys):
    assert run_repl(monkeypatch, "file kuka_lwr.txt speed=1000\n", "--port", str(server.port)) == 0
    captured = capsys.readouterr()
    assert "warning: kuka_lwr.txt is written for robot kuka_lwr" in captured.err
    assert "commands, all ok" in captured.out


LIMIT_LINE_3 = "degrees\nmove 0 10\nmove 1 500\nmove 2 20\n"


def test_an_error_reply_stops_the_play_with_status_1(server, tmp_path, capsys):
    path = write(tmp_path, "limit.txt", LIMIT_LINE_3)
    assert player.main([path, "--port", str(server.port)]) == 1
    captured = capsys.readouterr()
    assert f"{path}:3: error: joint_l (index 1) = 500 deg is outside its limits" in captured.err
    assert "[4/4]" not in captured.out
    q = server.q
    assert math.isclose(q[0], math.radians(10)) and q[1] == 0 and q[2] == 0


def test_keep_going_plays_every_line_but_still_fails(server, tmp_path, capsys):
    path = write(tmp_path, "limit.txt", LIMIT_LINE_3)
    assert player.main([path, "--port", str(server.port), "--keep-going"]) == 1
    captured = capsys.readouterr()
    assert "[4/4] move 2 20 -> ok" in captured.out
    assert "1 error" in captured.err
    assert math.isclose(server.q[2], math.radians(20))


def test_pipelined_play_matches_replies_to_lines(server, connect, tmp_path, capsys):
    assert (
        player.main([MOTOMAN, "--port", str(server.port), "--speed", "1e4", "--window", "8"]) == 0
    )
    out = capsys.readouterr().out
    assert [line.split("]")[0] for line in out.splitlines()[:16]] == [
        f"[{k:>2}/16" for k in range(1, 17)
    ]
    assert where_degrees(server, connect) == SEED_END
    path = write(tmp_path, "limit.txt", LIMIT_LINE_3)
    assert player.main([path, "--port", str(server.port), "--window", "8"]) == 1
    # Line 4 was already sent when line 3 failed: it has run, and its reply is shown.
    assert "[4/4] move 2 20 -> ok" in capsys.readouterr().out


def test_the_player_plays_motoman_txt_with_motion_on(c2rviz_process, capsys):
    # The real program, its arm given 20 rad/s, on virtual time: each move's reply still
    # waits for its arrival (the status below), by the program's clock, not seconds of wall.
    proc = c2rviz_process(
        "--no-viewer", "--speed", "100", "--max-velocity", "20", "--clock", "virtual"
    )
    args = [MOTOMAN, "--port", str(proc.port), "--speed", "1000", "--motion", "on"]
    assert player.main(args) == 0
    out = capsys.readouterr().out
    assert "[16/16] move 0,1 -90,-90 -> ok" in out and "16 commands, all ok" in out
    client = Client("127.0.0.1", proc.port)
    assert client.ask("degrees") == "ok"
    assert client.ask("where") == SEED_END  # where motion off ends too
    assert client.ask("status") == "ok idle"  # every move had arrived when its reply came
    client.close()


def test_the_player_sends_motion_before_the_first_line(server, tmp_path):
    path = write(tmp_path, "two.txt", "# robot: motoman_sia20d\ndegrees\nmove 0 5\n")
    assert player.main([path, "--port", str(server.port), "--motion", "on"]) == 0
    assert server.scene.commands[-3:] == ["motion on", "degrees", "move 0 5"]
    assert server.q[0] == pytest.approx(math.radians(5))


def test_the_player_refuses_a_bad_motion_mode(capsys):
    port = free_port()  # nothing listens: the option is refused before connecting
    with pytest.raises(SystemExit) as exit_:
        player.main([MOTOMAN, "--port", str(port), "--motion", "bogus"])
    assert exit_.value.code == 2
    assert "argument --motion: invalid choice: 'bogus'" in capsys.readouterr().err


def test_the_player_says_when_the_server_has_no_motion(old_server, capsys):
    before = old_server.q
    args = [MOTOMAN, "--port", str(old_server.port), "--motion", "on"]
    assert player.main(args) == 2
    err = capsys.readouterr().err
    assert "--motion on: the server replied \"error: unknown command 'motion'" in err
    assert "nothing was sent" in err
    assert old_server.q == before


MOTION_SCRIPT = (
    "# robot: motoman_sia20d\n"
    "motion on\nspeed 100\ndegrees\n"
    "move 0 10\nwhere\nmove 1 20\nj 0,0,0,0,0,0,0\nwhere\n"
)


@pytest.mark.parametrize("window", [1, 8])
def test_a_file_that_says_motion_on_plays_in_order(server, tmp_path, capsys, window):
    path = write(tmp_path, "motion.txt", MOTION_SCRIPT)
    assert player.main([path, "--check"]) == 0  # the server's parser knows motion
    assert player.main([path, "--port", str(server.port), "--window", str(window)]) == 0
    out = capsys.readouterr().out
    # Each `where` runs after the move before it has arrived, even when sent ahead.
    assert "[5/8] where -> ok 10,0,0,0,0,0,0" in out
    assert "[8/8] where -> ok 0,0,0,0,0,0,0" in out
    assert len(joints_lines(server)) == 1


def test_the_progress_shows_a_move_in_progress(server, tmp_path):
    path = Path(write(tmp_path, "moving.txt", "motion on\nspeed 100\nmove 0 0.2\nwhere\n"))
    out = io.StringIO()
    client = Client(server.host, server.port)
    try:
        errors = player.play(client, player.load_script(path), player.Progress(out, out, True))
    finally:
        client.close()
    assert errors == 0
    shown = out.getvalue()
    assert "\r\x1b[K[3/4] move 0 0.2 -> moving\r\x1b[K[3/4] move 0 0.2 -> ok" in shown
    assert "[2/4] speed 100 -> moving" not in shown and "where -> moving" not in shown
    assert "[4/4] where -> ok 0.2,0,0,0,0,0,0\n" in shown


def test_loop_plays_the_file_n_times(server, tmp_path, capsys):
    path = write(tmp_path, "two.txt", "# two lines\nmove 0 0.1\n\nmove 0 0.2\n")
    assert player.main([path, "--port", str(server.port), "--loop", "3"]) == 0
    out = capsys.readouterr().out
    assert "[3: 2/2] move 0 0.2 -> ok" in out
    assert "3 x 2 commands, all ok" in out


def test_lines_after_quit_would_never_run(tmp_path, capsys):
    path = write(tmp_path, "quit.txt", "home\nquit\nhome\n")
    assert player.main([path, "--check"]) == 2
    assert f"{path}:3: error: line 2 ('quit') closes the connection" in capsys.readouterr().err


def test_the_player_finds_bundled_files_and_reports_missing_ones(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert player.main(["motoman.txt", "--check"]) == 0
    assert player.main(["nonesuch.txt", "--check"]) == 2
    assert "no command file 'nonesuch.txt'" in capsys.readouterr().err


def test_the_player_gives_up_when_no_server_answers(tmp_path, capsys):
    # Gave up after its --timeout (not sooner); that it waits no longer is the dialer's
    # test above (test_client_gives_up_after_its_retry_time), judged on its pauses.
    assert player.main([MOTOMAN, "--port", str(free_port()), "--timeout", "0.3"]) == 1
    waited = re.search(
        r"no c2rviz server at 127\.0\.0\.1:\d+ after ([\d.]+) s", capsys.readouterr().err
    )
    assert waited is not None and float(waited.group(1)) >= 0.3


def test_in_place_progress_on_a_terminal():
    out = io.StringIO()
    show = player.Progress(out, out, in_place=True)
    show.step("[1/3]", "home", "ok")
    show.step("[2/3]", "where", "ok 0,0")
    show.step("[3/3]", "home", "ok")
    show.error("x.txt:3: error: boom")
    assert out.getvalue() == (
        "\r\x1b[K[1/3] home -> ok"
        "\r\x1b[K[2/3] where -> ok 0,0\n"  # a reply with data stays on screen
        "\r\x1b[K[3/3] home -> ok\n"
        "x.txt:3: error: boom\n"
    )


def test_progress_shows_a_reply_being_waited_for_only_on_a_terminal():
    out = io.StringIO()
    show = player.Progress(out, out, in_place=True)
    show.waiting("[1/2]", "j 1,2", "moving")
    show.step("[1/2]", "j 1,2", "ok")
    show.end_line()
    assert out.getvalue() == "\r\x1b[K[1/2] j 1,2 -> moving\r\x1b[K[1/2] j 1,2 -> ok\n"
    plain = io.StringIO()
    show = player.Progress(plain, plain, in_place=False)
    show.waiting("[1/2]", "j 1,2", "moving")
    show.step("[1/2]", "j 1,2", "ok")
    assert plain.getvalue() == "[1/2] j 1,2 -> ok\n"


def test_fileplayer_script_runs_as_a_process(server, connect):
    args = [PLAYER_SCRIPT, "commands/motoman.txt", "--port", str(server.port), "--speed", "1000"]
    done = subprocess.run(
        [sys.executable, *args], cwd=ROOT, capture_output=True, text=True, timeout=30, env=env()
    )
    assert done.returncode == 0, done.stderr
    assert "[16/16] move 0,1 -90,-90 -> ok" in done.stdout
    assert where_degrees(server, connect) == SEED_END
    bad = subprocess.run(
        [sys.executable, *args[:1], "nonesuch.txt"],
        capture_output=True,
        text=True,
        timeout=30,
        env=env(),
    )
    assert bad.returncode == 2 and "Traceback" not in bad.stderr


# --- the REPL, piped -----------------------------------------------------------------------


def test_repl_piped(old_server, connect, monkeypatch, capsys):
    server = old_server  # goto steps there
    text = (
        "file motoman.txt speed=1000\n"
        "where\n"
        "goto 10,20,0,0,0,0,0 step=5 rate=500\n"
        "frobnicate 3\n"
        "\n# a comment\n"
        "where\n"
        "sleep 0.01\n"
        "q\n"
    )
    assert run_repl(monkeypatch, text, "--port", str(server.port)) == 1  # a line got an error
    captured = capsys.readouterr()
    assert "Socket Created" in captured.err and "Socket Connected" in captured.err
    assert not any(line.startswith(">") for line in captured.out.splitlines())  # no prompt
    out = captured.out
    assert "[16/16] move 0,1 -90,-90 -> ok" in out
    # Piped, `where` is the server's own reply (the table is for a person at a terminal).
    assert "motoman_sia20d (degrees):" not in out
    assert out.count("ok -90,-90,0,0,0,0,0\n") == 1  # after the file
    assert "ok (goto: 22 steps" in out  # 110 degrees in 5-degree steps
    assert "error: unknown command 'frobnicate' (try 'help')" in out
    assert out.count("ok 10,20,0,0,0,0,0\n") == 1  # after goto
    # q leaves the server running
    assert where_degrees(server, connect) == "ok 10,20,0,0,0,0,0"


def test_piped_repl_exits_1_when_a_line_got_an_error(server, connect):
    """`c2rviz-cli < script` fails like the player, but still runs every line."""
    args = [sys.executable, REPL_SCRIPT, "--port", str(server.port)]
    clean = subprocess.run(
        args,
        input="degrees\nmove 0 10\nwhere\n",
        capture_output=True,
        text=True,
        timeout=30,
        env=env(),
    )
    assert clean.returncode == 0, clean.stderr
    script = "degrees\nmove 1 500\nmove 0 20\nwhere\n"
    failed = subprocess.run(
        args, input=script, capture_output=True, text=True, timeout=30, env=env()
    )
    assert failed.returncode == 1, failed.stderr
    assert "error: joint_l (index 1) = 500 deg is outside its limits" in failed.stdout
    assert where_degrees(server, connect) == "ok 20,0,0,0,0,0,0"  # the lines after it ran
    local = subprocess.run(
        args, input="goto 1\n", capture_output=True, text=True, timeout=30, env=env()
    )
    assert local.returncode == 1  # an error from a local command counts too
    assert "error: goto: joints needs 7 values, got 1" in local.stdout


def test_the_readmes_quick_start_runs_as_shown(server):
    """README's first example needs nothing but the installed client, and prints what it shows."""
    readme = (ROOT / "README.md").read_text()
    quick = readme.split("## Quick start")[1].split("\n## ")[0]
    command, shown = re.search(r"```sh\n(printf .*)\n```\n\n```\n(.*?)```", quick, re.S).groups()
    script, client = re.fullmatch(r"printf '(.*)' \| \.venv/bin/(c2rviz-cli)", command).groups()
    assert client == "c2rviz-cli" and "nc " not in command
    done = subprocess.run(
        [sys.executable, REPL_SCRIPT, "--port", str(server.port)],
        input=script.replace("\\n", "\n"),
        capture_output=True,
        text=True,
        timeout=60,
        env=env(),
    )
    said = shown.replace(":31000:", f":{server.port}:").splitlines()
    assert done.stderr.splitlines() == said[:2]  # the connection messages
    assert done.stdout.splitlines() == said[2:]  # the replies
    assert done.returncode == 1  # as the README says: a line got an error
    assert "sudo apt-get install netcat-openbsd" in quick


def test_repl_goto_in_radians_and_its_errors(old_server, monkeypatch, capsys):
    server = old_server  # goto steps there: step= and rate= apply
    text = (
        "goto 0.5,0,0,0,0,0,0 rate=1000\n"  # default step: 2 degrees = 0.0349 rad
        "goto 1,2\n"
        "goto 0,0,0,0,0,0,0 speed=3\n"
        "goto 0,0,0,9,0,0,0 step=1 rate=1000\n"  # joint_u's limit is 2.26 rad
        "help\n"
        "goto 0.5,1.91,0,0,0,0,0 step=1 rate=1000\n"  # exactly at joint_l's limit
    )
    assert run_repl(monkeypatch, text, "--port", str(server.port)) == 1  # a line got an error
    out = capsys.readouterr().out
    assert "ok (goto: 15 steps" in out
    assert "error: goto: joints needs 7 values, got 2" in out
    assert "error: goto: unknown option 'speed'" in out
    assert "error: goto: joint_u (index 3) = 9 rad is outside its limits -2.26..2.26 rad" in out
    assert "file NAME [speed=X]" in out and "marker sphere|cube|arrow|cylinder" in out
    assert "ok (goto: 2 steps" in out  # the refused goto moved nothing: 1.91 rad to go
    assert server.q[:2] == pytest.approx((0.5, 1.91))
    assert len(joints_lines(server)) == 15 + 2


def test_repl_goto_uses_the_servers_motion(server, monkeypatch, capsys):
    text = "degrees\nmotion follow\nspeed 100\ngoto 10,20,0,0,0,0,0 step=5\nmotion\n"
    assert run_repl(monkeypatch, text, "--port", str(server.port)) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[:3] == ["ok", "ok", "ok"]
    assert out[3].startswith("ok (goto: arrived in ")
    assert out[4] == "ok follow"  # the connection's mode is put back
    assert joints_lines(server) == ["joints 10.0,20.0,0.0,0.0,0.0,0.0,0.0"]  # one line
    assert server.q == pytest.approx((math.radians(10), math.radians(20), 0, 0, 0, 0, 0))


def test_repl_goto_reports_a_preempted_move(server, connect):
    """Another client's move ends the goto's: an error, and the mode is still put back."""
    with subprocess.Popen(
        [sys.executable, REPL_SCRIPT, "--port", str(server.port)],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env(),
    ) as proc:
        try:
            assert proc.stdin is not None
            proc.stdin.write("speed 10\ngoto 2,0,0,0,0,0,0\nmotion\n")  # seconds at 10 %
            proc.stdin.flush()
            probe = connect(server)
            deadline = time.monotonic() + 60
            while not probe.ask("status").startswith("ok moving"):
                assert time.monotonic() < deadline, "the goto did not start"
                time.sleep(0.01)
            assert probe.ask("j 0,0.1,0,0,0,0,0") == "ok"  # at once: it preempts the goto
            out, err = proc.communicate("", timeout=60)
        finally:
            proc.kill()
            proc.wait()
    assert proc.returncode == 1, err  # piped, a line got an error
    lines = out.splitlines()
    assert lines[0] == "ok"
    assert lines[1].startswith("goto: error: preempted by tcp 127.0.0.1:")
    assert lines[2] == "ok off"
    assert server.q == pytest.approx((0, 0.1, 0, 0, 0, 0, 0))


def test_repl_help_lists_each_command_once(server, monkeypatch, capsys):
    assert run_repl(monkeypatch, "help\n", "--port", str(server.port)) == 0
    listed = [line.split()[0] for line in capsys.readouterr().out.splitlines()[1:]]
    listed = [word for word in listed if word not in ("server", "local")]  # the two headings
    assert "where" in listed and "goto" in listed and "pose" in listed
    assert len(listed) == len(set(listed)), sorted(w for w in listed if listed.count(w) > 1)


def test_repl_help_verb_gives_one_line(server, monkeypatch, capsys):
    text = "help moveto\nhelp goto\nhelp nope\n"
    assert run_repl(monkeypatch, text, "--port", str(server.port)) == 1  # `help nope`: an error
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].startswith("ok moveto x,y,z[,roll,pitch,yaw] | marker N: ")
    assert lines[0].endswith("; see docs/cartesian.md")
    assert lines[1].startswith("goto v0,...,vn-1 [step=S] [rate=HZ]: move there")
    assert lines[1].endswith("(this client; see docs/clients.md)")
    assert lines[2] == "error: help: no verb 'nope' (usage: help [VERB])"
    assert len(lines) == 3


def test_repl_file_says_what_its_lines_left_set(server, tmp_path, monkeypatch, capsys):
    """Issue 39, rough edge 3: a file's lines act as if typed, so its `degrees` stays; the
    REPL says so (a bag, which names no unit, leaves the connection as it was)."""
    motion = write(tmp_path, "motion.txt", "motion on\nradians\nhome\n")
    text = (
        f"file motoman.txt speed=1000\nwhere\nfile motoman.txt speed=1000\nfile {motion}\nmotion\n"
    )
    assert run_repl(monkeypatch, text, "--port", str(server.port)) == 0
    captured = capsys.readouterr()
    notes = [line for line in captured.err.splitlines() if " left this connection " in line]
    assert notes == [
        "motoman.txt left this connection in degrees ('radians' goes back), as its lines say",
        f"{motion} left this connection in radians ('degrees' goes back) and in motion on, "
        "as its lines say",
    ]  # the second motoman.txt changed nothing: no note
    assert "\nok -90,-90,0,0,0,0,0\n" in captured.out  # `where` in degrees, as the file said
    assert captured.out.endswith("\nok on\n")


def test_repl_file_stops_at_the_first_error(server, tmp_path, monkeypatch, capsys):
    bad = write(tmp_path, "bad.txt", BAD_LINE_3)
    limit = write(tmp_path, "limit.txt", LIMIT_LINE_3)
    text = f"file {bad}\nfile {limit}\nfile nonesuch.txt\nwhere\n"
    assert run_repl(monkeypatch, text, "--port", str(server.port)) == 1  # a line got an error
    out = capsys.readouterr().out
    assert f"{bad}:3: error: unknown command 'mvoe'" in out
    assert f"{limit}:3: error: joint_l (index 1) = 500 deg" in out
    assert "[4/4]" not in out
    assert "error: file: no command file 'nonesuch.txt'" in out
    assert out.split("nonesuch")[-1].endswith("\nok 10,0,0,0,0,0,0\n")  # still in degrees


def test_repl_quit_stops_the_server(c2rviz_process, monkeypatch, capsys):
    proc = c2rviz_process("--no-viewer")
    assert run_repl(monkeypatch, "where\nquit\n", "--port", str(proc.port)) == 0
    assert capsys.readouterr().out.splitlines()[-1] == "ok"
    assert proc.wait(timeout=10) == 0


def test_repl_waits_for_a_server_that_starts_late(c2rviz_process):
    port = free_port()
    with subprocess.Popen(
        [sys.executable, REPL_SCRIPT, "--port", str(port), "--timeout", "120"],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env(),
    ) as repl_proc:
        try:
            assert repl_proc.stderr is not None
            said = b""
            while b"retrying" not in said:  # it has tried once, found nothing, and waits
                ready, _, _ = select.select([repl_proc.stderr], [], [], 60)
                chunk = os.read(repl_proc.stderr.fileno(), 4096) if ready else b""
                assert chunk, f"the REPL said {said!r} and then nothing"
                said += chunk
            assert repl_proc.poll() is None
            c2rviz_process("--no-viewer", "--port", str(port))
            out, err = repl_proc.communicate("where\nq\n", timeout=120)
            err = said.decode() + err
        finally:
            repl_proc.kill()
            repl_proc.wait()
    assert repl_proc.returncode == 0, err
    assert f"no server at 127.0.0.1:{port} yet" in err and "retrying" in err
    assert "Socket Connected" in err
    assert out == "ok 0,0,0,0,0,0,0\n"  # piped: the server's own reply


def test_repl_gives_up_with_a_clear_message():
    port = free_port()
    done = subprocess.run(  # gave up after --timeout (no longer: the dialer's test above)
        [sys.executable, REPL_SCRIPT, "--port", str(port), "--timeout", "1"],
        input="where\n",
        capture_output=True,
        text=True,
        timeout=120,  # a hang guard, generous for a busy machine
        env=env(),
    )
    assert done.returncode == 1
    waited = re.search(rf"no c2rviz server at 127\.0\.0\.1:{port} after ([\d.]+) s", done.stderr)
    assert waited is not None and float(waited.group(1)) >= 1.0, done.stderr
    assert "giving up" in done.stderr
    assert "Traceback" not in done.stderr + done.stdout


# --- the REPL on a terminal ----------------------------------------------------------------

# Make the pseudo-terminal the child's controlling terminal, so ^C and ^D act as typed,
# and undo an inherited "ignore SIGINT" (background jobs get one), as a login shell would.
LAUNCH = (
    "import fcntl, os, signal, sys, termios; fcntl.ioctl(0, termios.TIOCSCTTY, 0); "
    "signal.signal(signal.SIGINT, signal.SIG_DFL); "
    "os.execv(sys.executable, [sys.executable, *sys.argv[1:]])"
)


class Terminal:
    """A process on a pseudo-terminal: ``send`` keystrokes, ``expect`` output."""

    def __init__(self, *args: str, history: Path) -> None:
        master, slave = os.openpty()
        self.proc = subprocess.Popen(
            [sys.executable, "-c", LAUNCH, *args],
            stdin=slave,
            stdout=slave,
            stderr=slave,
            start_new_session=True,
            env={**env(), "C2RVIZ_HISTORY": str(history)},
        )
        os.close(slave)
        self.master = master
        self.seen = ""

    def send(self, keys: str) -> None:
        os.write(self.master, keys.encode())

    def expect(self, text: str, timeout: float = 60.0) -> str:
        """Wait until ``text`` appears; return the output up to it and consume it."""
        deadline = time.monotonic() + timeout
        while text not in self.seen:
            left = deadline - time.monotonic()
            ready, _, _ = select.select([self.master], [], [], max(0.0, left))
            if not ready:
                raise AssertionError(f"no {text!r} after {timeout} s; got {self.seen!r}")
            try:
                data = os.read(self.master, 65536)
            except OSError:  # EIO: the child closed the terminal
                data = b""
            if not data:
                raise AssertionError(f"terminal closed before {text!r}; got {self.seen!r}")
            self.seen += data.decode(errors="replace").replace("\r\n", "\n")
        cut = self.seen.index(text) + len(text)
        before, self.seen = self.seen[:cut], self.seen[cut:]
        return before

    def finish(self, timeout: float = 60.0) -> tuple[int, str]:
        """Wait for the exit; return the status and the rest of the output."""
        status = self.proc.wait(timeout=timeout)
        while select.select([self.master], [], [], 0.2)[0]:
            try:
                data = os.read(self.master, 65536)
            except OSError:
                break
            if not data:
                break
            self.seen += data.decode(errors="replace")
        return status, self.seen

    def wait_blocked_in(self, *kernel_functions: str, fallback_s: float) -> None:
        """Wait until the process sleeps in one of ``kernel_functions`` (``/proc/PID/wchan``).

        ``hrtimer_nanosleep`` is ``time.sleep``; ``poll_schedule_timeout`` or
        ``do_select`` is readline waiting for a key. Where the kernel does not say
        (wchan hidden), wait ``fallback_s`` instead.
        """
        deadline = time.monotonic() + 60
        while True:
            try:
                where = Path(f"/proc/{self.proc.pid}/wchan").read_text().strip()
            except OSError:
                where = "0"
            if where in ("", "0"):
                time.sleep(fallback_s)
                return
            if any(name in where for name in kernel_functions):
                return
            assert time.monotonic() < deadline, f"still in {where!r}, not {kernel_functions}"
            time.sleep(0.02)

    def close(self) -> None:
        if self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait()
        os.close(self.master)


@pytest.fixture
def terminal(tmp_path) -> Callable[..., Terminal]:
    opened: list[Terminal] = []

    def start(*args: str) -> Terminal:
        term = Terminal(REPL_SCRIPT, *args, history=tmp_path / "history")
        opened.append(term)
        return term

    yield start
    for term in opened:
        term.close()


def test_repl_on_a_terminal(server, connect, terminal, tmp_path):
    term = terminal("--port", str(server.port))
    term.expect("Socket Created")
    term.expect("Socket Connected")
    term.expect("> ")
    term.send("file motoman.txt speed=1000\n")
    term.expect("16 commands, all ok")
    term.send("where\n")
    assert "1  joint_l  -90" in term.expect("joint_t")
    term.send("goto 0,0,0,0,0,0,0 rate=1000\n")
    term.expect("ok (goto: arrived in")  # the server's motion: rate= does not apply
    term.send("bogus\n")
    term.expect("error: unknown command 'bogus'")
    term.send("sleep 30\n")
    term.wait_blocked_in("nanosleep", fallback_s=0.5)  # the local sleep has begun
    term.send("\x03")  # Ctrl-C stops the command, not the REPL
    term.expect("interrupted")
    term.send("where\n")
    term.expect("joint_t")
    term.send("q\n")
    status, rest = term.finish()
    assert status == 0
    assert "Traceback" not in rest
    assert where_degrees(server, connect) == "ok 0,0,0,0,0,0,0"  # the server is still up
    history = (tmp_path / "history").read_text()
    assert "file motoman.txt speed=1000" in history and "bogus" in history


def test_ctrl_c_stops_a_goto_on_the_robot_the_repl_drives(cell, connect, terminal):
    term = terminal("--port", str(cell.port))
    term.expect("> ")
    term.send("robot right\n")
    term.expect("ok\n")
    term.send("speed 10\n")
    term.expect("ok\n")
    term.send("goto 2,0,0,0,0,0,0\n")  # lwr_0_joint to 2 rad at 10 % of its limits: seconds
    probe = connect(cell)
    assert probe.ask("robot right") == "ok"
    deadline = time.monotonic() + 60
    while float(probe.ask("where")[3:].split(",")[0]) < 0.01:  # it has set off
        assert time.monotonic() < deadline, "the goto did not start"
        time.sleep(0.01)
    term.send("\x03")  # Ctrl-C: stop, on another connection, for robot right
    term.expect("goto: interrupted, the arm stopped: error: motion stopped by tcp 127.0.0.1:")
    assert probe.ask("status") == "ok idle"
    stopped = float(probe.ask("where")[3:].split(",")[0])
    assert 0.01 < stopped < 2
    term.send("motion\n")
    term.expect("ok off")  # put back, on a connection still in step
    term.send("where\n")
    term.expect("lwr_6_joint")
    term.send("q\n")
    status, rest = term.finish()
    assert status == 0 and "Traceback" not in rest


@pytest.mark.parametrize("key", ["\x04", "\x03"], ids=["ctrl-d", "ctrl-c"])
def test_repl_leaves_cleanly_on_ctrl_d_and_ctrl_c(server, terminal, key):
    term = terminal("--port", str(server.port))
    term.expect("> ")
    # CPython's readline misses a SIGINT that lands between drawing the prompt and
    # waiting for input (a race no typist can hit): wait until it waits.
    term.wait_blocked_in("poll_schedule_timeout", "select", "poll", fallback_s=0.3)
    term.send(key)
    status, rest = term.finish()
    assert status == 0
    assert "Traceback" not in rest


def test_repl_reconnects_when_the_server_restarts(c2rviz_process, terminal):
    port = free_port()
    first = c2rviz_process("--no-viewer", "--port", str(port))
    term = terminal("--port", str(port), "--timeout", "30")
    term.expect("> ")
    term.send("degrees\n")
    term.expect("ok")
    first.popen.send_signal(signal.SIGTERM)
    assert first.wait() == 0
    c2rviz_process("--no-viewer", "--port", str(port))
    term.send("where\n")
    term.expect("lost (the server stopped or restarted); reconnecting")
    assert "motoman_sia20d (degrees):" in term.expect("joint_t")  # units restored
    term.send("q\n")
    assert term.finish()[0] == 0


def test_connection_module_names_the_bundled_commands_dir():
    assert (dialing.COMMANDS_DIR / "motoman.txt").is_file()
