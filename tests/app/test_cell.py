"""Several robots in one cell: one world, a command server per robot, robots by name."""

from __future__ import annotations

import asyncio
import math
import os
import re
import socket
import subprocess
import sys
import threading
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from support import ROOT, Client, load_robot
from watch_support import read_until

from c2rviz.app.cli import main
from c2rviz.app.members import load_cell
from c2rviz.collision import first_hit_between
from c2rviz.errors import ConfigError
from c2rviz.session import Services
from c2rviz.transports.tcp_server import CommandServer
from c2rviz.world.observer import RecordingScene
from c2rviz.world.world import World

LEFT = "0,0,0,0,0,0"
RIGHT = "1.2,0,0,0,0,180"


def se3(x: float, y: float, z: float, roll: float, pitch: float, yaw: float) -> pin.SE3:
    return pin.SE3(pin.rpy.rpyToMatrix(roll, pitch, yaw), np.array([x, y, z]))


class CellThread:
    """A world of several robots and a real command server for each, on one loop."""

    def __init__(self, robots: dict[str, str], origins: dict[str, pin.SE3]) -> None:
        self.loop = asyncio.new_event_loop()
        self.scene = RecordingScene()
        self.world = World(
            {name: load_robot(model) for name, model in robots.items()},
            self.scene,
            origins=origins,
        )
        self.services = Services(self.world)
        self.thread = threading.Thread(target=self.loop.run_forever, daemon=True)
        self.thread.start()
        self.servers: dict[str, CommandServer] = {}
        self.ports: dict[str, int] = {}
        for name in robots:
            server = CommandServer(self.services, robot=name)
            _, port = self.run(server.start("127.0.0.1", 0))
            self.world.state(name).port = port
            self.servers[name], self.ports[name] = server, port

    def run(self, coro):  # type: ignore[no-untyped-def]
        return asyncio.run_coroutine_threadsafe(coro, self.loop).result(timeout=10)

    def call(self, fn):  # type: ignore[no-untyped-def]
        async def on_loop():  # type: ignore[no-untyped-def]
            return fn()

        return self.run(on_loop())

    def client(self, name: str) -> Client:
        return Client("127.0.0.1", self.ports[name])

    def stop(self) -> None:
        for server in self.servers.values():
            self.run(server.stop())
        self.loop.call_soon_threadsafe(self.loop.stop)
        self.thread.join(timeout=10)
        self.loop.close()


@pytest.fixture
def cell() -> Iterator[CellThread]:
    made = CellThread(
        {"left": "motoman_sia20d", "right": "fanuc_lrmate200id"},
        {"left": se3(0, 0, 0, 0, 0, 0), "right": se3(1.2, 0, 0, 0, 0, math.pi)},
    )
    clients: list[Client] = []
    made.client = lambda name, client=made.client: clients.append(client(name)) or clients[-1]  # type: ignore[method-assign]
    yield made
    for client in clients:
        client.close()
    made.stop()


def test_each_port_drives_its_own_robot(cell: CellThread):
    left, right = cell.client("left"), cell.client("right")
    assert left.ask("names").startswith("ok left joint_s,")  # the name the cell gives it
    assert right.ask("names").startswith("ok right joint_1,")
    assert left.ask("robot") == "ok left" and right.ask("robot") == "ok right"
    left.ask("degrees")
    right.ask("degrees")
    left.send("j 10,0,0,0,0,0,0\n" * 50)
    right.send("j 0,20,0,0,0,0\n" * 50)
    assert [left.read_line() for _ in range(50)] == ["ok"] * 50
    assert [right.read_line() for _ in range(50)] == ["ok"] * 50
    assert left.ask("where") == "ok 10,0,0,0,0,0,0"
    assert right.ask("where") == "ok 0,20,0,0,0,0"
    assert cell.ports["left"] != cell.ports["right"]
    assert left.ask("robots") == f"ok left:{cell.ports['left']},right:{cell.ports['right']}"


def test_robot_switches_a_connection_and_an_unknown_name_changes_nothing(cell: CellThread):
    client = cell.client("left")
    client.ask("degrees")
    assert client.ask("robot nobody") == "error: no robot 'nobody' here; robots: left, right"
    assert client.ask("robot") == "ok left"
    assert client.ask("robot right") == "ok"
    assert client.ask("j 0,30,0,0,0,0") == "ok"  # 6 joints now: the Fanuc
    assert client.ask("where") == "ok 0,30,0,0,0,0"
    assert client.ask("robot left") == "ok"
    assert client.ask("where") == "ok 0,0,0,0,0,0,0"  # units stayed degrees
    assert cell.client("right").ask("where").startswith("ok 0,0.5235987756,")


def test_markers_in_the_base_frame_and_in_the_world_frame(cell: CellThread):
    client = cell.client("right")
    assert client.ask("mark 0.5,0,0.2,0,0,0") == "ok"
    assert client.ask("mark world 0.5,0,0.2,0,0,0") == "ok"
    base, world = cell.call(lambda: list(cell.world.state("right").markers))
    robot = load_robot("fanuc_lrmate200id")
    expected = se3(1.2, 0, 0, 0, 0, math.pi) * robot.base_placement
    np.testing.assert_allclose(base.position, expected * np.array([0.5, 0.0, 0.2]), atol=1e-12)
    np.testing.assert_allclose(world.position, [0.5, 0.0, 0.2], atol=1e-12)


def test_watch_events_name_only_their_own_robot(cell: CellThread):
    """A stop of one robot is `event stopped` for its watchers only; the other robot's
    watchers see their move arrive, and its markers in its own base frame."""
    watchers = {name: cell.client(name) for name in ("left", "right")}
    movers = {name: cell.client(name) for name in ("left", "right")}
    seen: dict[str, list[str]] = {name: [] for name in watchers}
    for watcher in watchers.values():
        assert watcher.ask("watch 1000") == "ok"
    for name, target in (("left", "60,30,0,0,0,0,0"), ("right", "0,40,0,0,0,0")):
        for line in ("degrees", "motion follow", "speed 10", f"j {target}"):
            assert movers[name].ask(line) == "ok"
    for name, watcher in watchers.items():  # both on their way
        read_until(
            watcher,
            lambda line: line.startswith("state") and "0,0,0,0,0,0" not in line,
            seen[name],
        )
    assert movers["left"].ask("stop") == "ok"  # at rest
    read_until(watchers["left"], lambda line: line.startswith("event"), seen["left"])
    assert seen["left"][-1] == "event stopped"
    assert movers["right"].ask("mark 0.5,0,0.2,0,0,0") == "ok"
    read_until(watchers["right"], lambda line: line.startswith("event"), seen["right"])
    assert seen["right"][-1] == "event marker 0.5,0,0.2,0,0,0 sphere 1,0,0"
    read_until(watchers["right"], lambda line: line.startswith("event"), seen["right"])
    assert seen["right"][-1] == "event arrived"
    assert not [line for line in seen["right"] if line == "event stopped"]


def test_a_switch_keeps_speed_and_marker_style_and_pose_stays_in_the_base_frame(
    cell: CellThread,
):
    client = cell.client("left")
    for line in ("speed 30", "marker cube", "color 0,1,0", "robot right"):
        assert client.ask(line) == "ok"
    assert client.ask("speed") == "ok 30"
    assert client.ask("mark 0.4,0,0.3,0,0,0") == "ok"
    (marker,) = cell.call(lambda: list(cell.world.state("right").markers))
    assert (marker.shape, marker.rgb) == ("cube", (0.0, 1.0, 0.0))
    # The Fanuc stands at x = 1.2 m, turned round: its pose is in its own base frame.
    fanuc = load_robot("fanuc_lrmate200id")
    home = fanuc.ee_pose(fanuc.home)
    expected = [*home.translation, *pin.rpy.matrixToRpy(home.rotation)]
    got = [float(v) for v in client.ask("pose").removeprefix("ok ").split(",")]
    np.testing.assert_allclose(got, expected, atol=1e-9)


def test_the_seeds_command_line_client_drives_the_second_robot(cell: CellThread):
    """`python clients/socketcmdline.py --port <right's port>` drives the Fanuc."""
    script = "degrees\nj 0,30,0,0,0,0\nwhere\nnames\n"
    done = subprocess.run(
        [
            sys.executable,
            str(ROOT / "clients" / "socketcmdline.py"),
            "--port",
            str(cell.ports["right"]),
        ],
        input=script,
        capture_output=True,
        text=True,
        timeout=120,
        cwd=ROOT,
    )
    assert done.returncode == 0, done.stderr
    assert "ok 0,30,0,0,0,0\n" in done.stdout  # piped: the server's own reply (issue 30.9)
    assert "ok right joint_1," in done.stdout
    assert cell.call(lambda: cell.world.state("right").q)[1] == pytest.approx(math.radians(30))
    assert cell.call(lambda: cell.world.state("left").q) == (0.0,) * 7


def test_the_same_model_twice_with_different_origins() -> None:
    cell = CellThread(
        {"a": "motoman_sia20d", "b": "motoman_sia20d"},
        {"a": se3(0, -0.8, 0, 0, 0, 0), "b": se3(0, 0.8, 0, 0, 0, 0)},
    )
    try:
        a, b = cell.client("a"), cell.client("b")
        a.ask("rand")
        assert b.ask("where") == "ok 0,0,0,0,0,0,0"
        assert a.ask("mark") == b.ask("mark") == "ok"
        ma, mb = cell.call(
            lambda: (cell.world.state("a").markers[0], cell.world.state("b").markers[0])
        )
        assert mb.position[1] == pytest.approx(
            0.8 + load_robot().ee_pose(load_robot().home).translation[1]
        )
        assert ma.position != mb.position
        a.close()
        b.close()
    finally:
        cell.stop()


CELL_INI = """
[options]
robot = motoman_sia20d

[motoman_sia20d]
base = base_link
eelink = link_t
urdf = {root}/robots/motoman_sia20d/robot.urdf

[fanuc_lrmate200id]
base = base_link
eelink = link_6
urdf = {root}/robots/fanuc_lrmate200id/robot.urdf

[cell:twoarms]
robots = left right

[left]
robot = motoman_sia20d
origin = 0,0,0,0,0,0
port = 31000

[right]
robot = fanuc_lrmate200id
origin = 1.2,0,0,0,0,180
port = 31001
"""


def write_ini(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "cell.ini"
    path.write_text(text.format(root=ROOT))
    return path


def test_a_cell_from_the_ini(tmp_path: Path):
    ini = write_ini(tmp_path, CELL_INI)
    for spec, where in (("twoarms", ini), (str(ini), None)):
        cell = load_cell(spec, where)
        assert cell.name == "twoarms"
        assert [(m.name, m.entry.name, m.port) for m in cell.members] == [
            ("left", "motoman_sia20d", 31000),
            ("right", "fanuc_lrmate200id", 31001),
        ]
        assert cell.members[1].origin == pytest.approx((1.2, 0, 0, 0, 0, math.pi))


def test_a_member_may_be_a_urdf_of_its_own(tmp_path: Path):
    """`[right]` with `urdf = ...` (and base, eelink, tool) instead of `robot = NAME`."""
    text = CELL_INI.replace(
        "[right]\nrobot = fanuc_lrmate200id\n",
        "[right]\nurdf = {root}/robots/kuka_lwr/robot.urdf\nbase = lwr_base_link\n"
        "eelink = lwr_7_link\ntool = 0,0,0.1,0,0,0\n",
    )
    cell = load_cell("twoarms", write_ini(tmp_path, text))
    right = cell.members[1]
    assert (right.name, right.entry.name, right.port) == ("right", "right", 31001)
    assert right.entry.urdf == ROOT / "robots" / "kuka_lwr" / "robot.urdf"
    assert (right.entry.base, right.entry.eelink) == ("lwr_base_link", "lwr_7_link")
    assert right.extras == (("tool", "0,0,0.1,0,0,0"),)
    assert right.origin == pytest.approx((1.2, 0, 0, 0, 0, math.pi))
    bad = text.replace("tool = 0,0,0.1,0,0,0", "colour = red")
    with pytest.raises(ConfigError, match="unknown key 'colour' in \\[right\\]"):
        load_cell("twoarms", write_ini(tmp_path, bad))


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (("port = 31001", "port = 31000"), "uses port 31000 twice (left and right)"),
        (("robot = fanuc_lrmate200id", "robot = nosuch"), "unknown robot 'nosuch'"),
        (("origin = 1.2,0,0,0,0,180", "origin = 1.2,0,0,0,0"), "origin = '1.2,0,0,0,0' must be 6"),
        (("origin = 1.2,0,0,0,0,180", "origin = a,0,0,0,0,0"), "must be 6 numbers"),
        (("robots = left right", "robots = left left"), "uses name left twice"),
        (("robots = left right", "robots = left middle"), "names robot 'middle', which has no"),
        (("port = 31001", "port = 70000"), "[right] port = 70000 is outside 0..65535"),
        (("port = 31001", "colour = red"), "unknown key 'colour' in [right]"),
    ],
    ids=[
        "duplicate-port",
        "unknown-robot",
        "five-numbers",
        "bad-number",
        "name-twice",
        "no-section",
        "port-range",
        "unknown-key",
    ],
)
def test_bad_cells_name_what_is_wrong(tmp_path: Path, change: tuple[str, str], message: str):
    ini = write_ini(tmp_path, CELL_INI.replace(*change))
    with pytest.raises(ConfigError) as caught:
        load_cell("twoarms", ini)
    assert message in str(caught.value)
    assert "\n" not in str(caught.value)


def test_an_unknown_cell_lists_the_cells(tmp_path: Path):
    ini = write_ini(tmp_path, CELL_INI)
    with pytest.raises(ConfigError, match=r"no \[cell:three\] in .* \(choose from: twoarms\)"):
        load_cell("three", ini)


@pytest.mark.xdist_group("default_ports")  # binds a default port: one at a time
def test_the_program_serves_a_cell(tmp_path: Path):
    """``c2rviz --cell FILE``: every robot on its own port, named in the banner."""
    ini = write_ini(
        tmp_path, CELL_INI.replace("port = 31000", "port = 0").replace("port = 31001", "port = 0")
    )
    proc = subprocess.Popen(
        [sys.executable, "-m", "c2rviz", "--cell", str(ini), "--no-viewer"],
        cwd=ROOT,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        env={**os.environ, "PYTHONUNBUFFERED": "1"},
    )
    try:
        assert proc.stdout is not None
        ports: dict[str, int] = {}
        lines = []
        while len(ports) < 2:
            line = proc.stdout.readline()
            assert line, "c2rviz stopped:\n" + "".join(lines)
            lines.append(line)
            if m := re.search(r"c2rviz: (\w+): commands on [\d.]+:(\d+)", line):
                ports[m.group(1)] = int(m.group(2))
        assert "c2rviz: cell twoarms: left, right\n" in lines
        assert any(
            line.startswith("c2rviz: right (model fanuc_lrmate200id), chain") for line in lines
        )
        left, right = Client("127.0.0.1", ports["left"]), Client("127.0.0.1", ports["right"])
        assert left.ask("robot") == "ok left" and right.ask("robot") == "ok right"
        assert right.ask("robots") == f"ok left:{ports['left']},right:{ports['right']}"
        assert left.ask("quit") == "ok"
        left.close()
        right.close()
        assert proc.wait(timeout=60) == 0
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
        assert proc.stdout is not None
        proc.stdout.close()


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (("port = 31001", "port = 31000"), "uses port 31000 twice"),
        (("robot = fanuc_lrmate200id", "robot = nosuch"), "unknown robot 'nosuch'"),
        (("origin = 1.2,0,0,0,0,180", "origin = 1.2,0,0,0,0"), "must be 6 numbers"),
    ],
    ids=["duplicate-port", "unknown-robot", "five-numbers"],
)
def test_a_bad_cell_exits_2_with_one_sentence(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], change: tuple[str, str], message: str
):
    ini = write_ini(tmp_path, CELL_INI.replace(*change))
    assert main(["--cell", str(ini), "--no-viewer"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("c2rviz: ") and message in err and err.count("\n") == 1


def test_a_cell_port_in_use_exits_2(tmp_path: Path, capsys: pytest.CaptureFixture[str]):
    with socket.socket() as busy:
        busy.bind(("127.0.0.1", 0))
        busy.listen()
        taken = busy.getsockname()[1]
        text = CELL_INI.replace("port = 31000", "port = 0").replace(
            "port = 31001", f"port = {taken}"
        )
        assert main(["--cell", str(write_ini(tmp_path, text)), "--no-viewer"]) == 2
    assert f"cannot listen for commands on 127.0.0.1:{taken}" in capsys.readouterr().err


def test_the_seeds_file_plays_on_one_robot_while_another_moves(cell: CellThread, capsys):
    """The seed's motoman.txt through the player on the left port while a client of the
    right robot sends `rand` in a loop: each ends where its own commands put it."""
    from c2rviz.clients import player

    stop = threading.Event()
    right_answers: list[str] = []

    def busy() -> None:
        client = Client("127.0.0.1", cell.ports["right"])
        try:
            while not stop.is_set():
                right_answers.append(client.ask("rand"))
            right_answers.append(client.ask("where"))
        finally:
            client.close()

    mover = threading.Thread(target=busy)
    mover.start()
    try:
        motoman = str(ROOT / "commands" / "motoman.txt")
        assert player.main([motoman, "--port", str(cell.ports["left"]), "--speed", "1000"]) == 0
    finally:
        stop.set()
        mover.join(timeout=60)
    left = cell.client("left")
    left.ask("degrees")
    assert left.ask("where") == "ok -90,-90,0,0,0,0,0"  # the seed script's end pose
    assert len(right_answers) > 1 and set(right_answers[:-1]) == {"ok"}
    right_q = cell.call(lambda: cell.world.state("right").q)
    assert right_answers[-1] == "ok " + ",".join(
        f"{v:.10g}" if abs(v) > 1e-9 else "0" for v in right_q
    )
    assert right_q != load_robot("fanuc_lrmate200id").home


def test_a_guarded_move_into_the_other_robot_is_refused() -> None:
    """Two motomans 0.9 m apart: swinging one's arm out towards the other collides."""
    cell = CellThread(
        {"a": "motoman_sia20d", "b": "motoman_sia20d"},
        {"a": se3(0, -0.45, 0, 0, 0, 0), "b": se3(0, 0.45, 0, 0, 0, 0)},
    )
    try:
        a, b = cell.client("a"), cell.client("b")
        for line in ("degrees", "guard on"):
            assert a.ask(line) == "ok"
        reply = a.ask("j 90,90,0,0,0,0,0")  # the arm held out level, towards b
        assert re.fullmatch(r"error: link_\w+ would hit b/\w+ at the target", reply), reply
        assert a.ask("where") == "ok 0,0,0,0,0,0,0"
        assert a.ask("j -90,90,0,0,0,0,0") == "ok"  # away from b: free
        a.ask("motion on")
        a.ask("speed 100")
        reply = a.ask("j 90,90,0,0,0,0,0")  # from -90 through 0 to +90: into b on the way
        match = re.fullmatch(r"error: link_\w+ would hit b/\w+ at (\d+)% of the move", reply)
        assert match and 50 <= int(match.group(1)) <= 100, reply
        assert a.ask("status") == "ok idle"
        assert b.ask("collisions") == "ok none"  # each robot alone is free
        a.close()
        b.close()
    finally:
        cell.stop()


BUNDLED_ONLY_CELL = """
[cell:pair]
robots = a b

[a]
robot = motoman_sia20d

[b]
robot = kuka_lwr
origin = 1.5,0,0,0,0,180
"""


def serve_until_ports(args: list[str], cwd: Path, count: int) -> tuple[subprocess.Popen, dict]:
    """Start ``python -m c2rviz ARGS`` in ``cwd``; return it once ``count`` ports are up."""
    proc = subprocess.Popen(
        [sys.executable, "-m", "c2rviz", *args, "--no-viewer"],
        cwd=cwd,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        env={**os.environ, "PYTHONUNBUFFERED": "1"},
    )
    assert proc.stdout is not None
    ports: dict[str, int] = {}
    lines = []
    while len(ports) < count:
        line = proc.stdout.readline()
        if not line:
            proc.wait(timeout=60)
            proc.stdout.close()
            raise AssertionError("c2rviz stopped:\n" + "".join(lines))
        lines.append(line)
        if m := re.search(r"c2rviz: (?:(\w+): )?commands on [\d.]+:(\d+)", line):
            ports[m.group(1) or "robot"] = int(m.group(2))
    return proc, ports


def stop(proc: subprocess.Popen, port: int) -> None:
    client = Client("127.0.0.1", port)
    assert client.ask("quit") == "ok"
    client.close()
    assert proc.wait(timeout=60) == 0
    assert proc.stdout is not None
    proc.stdout.close()


def free_port_pair() -> int:
    """A port P such that P and P + 1 are free now."""
    for _ in range(100):
        with socket.socket() as probe:
            probe.bind(("127.0.0.1", 0))
            port = probe.getsockname()[1]
        if port < 65535:
            with socket.socket() as a, socket.socket() as b:
                try:
                    a.bind(("127.0.0.1", port))
                    b.bind(("127.0.0.1", port + 1))
                except OSError:
                    continue
            return port
    raise AssertionError("no two free ports in a row")


@pytest.mark.xdist_group("default_ports")  # binds a default port: one at a time
def test_a_cell_file_and_a_users_ini_name_the_bundled_robots(tmp_path: Path):
    """Issue 30.1: a cell file of its own, and an ini with only the user's robot, can
    name motoman_sia20d and kuka_lwr (the bundled robots), from any folder."""
    cell = tmp_path / "pair.ini"
    cell.write_text(BUNDLED_ONLY_CELL)
    proc, ports = serve_until_ports(["--cell", str(cell), "--port", "0"], tmp_path, 2)
    stop(proc, ports["a"])
    own = tmp_path / "cmdinterpreter.ini"
    own.write_text(
        f"[myarm]\nurdf = {ROOT / 'robots/fanuc_lrmate200id/robot.urdf'}\n"
        "base = base_link\neelink = link_6\n"
    )
    proc, ports = serve_until_ports(["--robot", "motoman_sia20d", "--port", "0"], tmp_path, 1)
    client = Client("127.0.0.1", ports["robot"])
    assert client.ask("names").startswith("ok motoman_sia20d joint_s,")
    client.close()
    stop(proc, ports["robot"])


@pytest.mark.xdist_group("default_ports")  # binds a default port: one at a time
def test_port_gives_a_cell_its_first_port(tmp_path: Path):
    """Issue 30.2: `--cell twoarms --port P` serves its members at P and P + 1 (the flag wins
    over the ports the ini fixes)."""
    base = free_port_pair()
    proc, ports = serve_until_ports(["--cell", "twoarms", "--port", str(base)], ROOT, 2)
    assert ports == {"left": base, "right": base + 1}
    stop(proc, base)


@pytest.fixture
def twins() -> Iterator[CellThread]:
    """Two motomans 0.9 m apart along y, each on its own port."""
    made = CellThread(
        {"a": "motoman_sia20d", "b": "motoman_sia20d"},
        {"a": se3(0, -0.45, 0, 0, 0, 0), "b": se3(0, 0.45, 0, 0, 0, 0)},
    )
    yield made
    made.stop()


def test_collisions_report_the_pairs_between_robots(twins: CellThread) -> None:
    """Each robot names its own link, then the other robot's: ``link_b~b/link_s``."""
    a, b = twins.client("a"), twins.client("b")
    try:
        for line in ("degrees", "j 90,90,0,0,0,0,0"):  # unguarded: a's arm into b
            assert a.ask(line) == "ok"
        mine = a.ask("collisions")
        assert re.fullmatch(r"ok (link_\w+~b/\w+,?)+", mine), mine
        theirs = b.ask("collisions")
        assert re.fullmatch(r"ok (\w+~a/link_\w+,?)+", theirs), theirs
        assert {p.split("~")[0] for p in mine[3:].split(",")} == {
            p.split("~")[1][2:] for p in theirs[3:].split(",")
        }
        assert a.ask("home") == "ok"
        assert a.ask("collisions") == "ok none" and b.ask("collisions") == "ok none"
    finally:
        a.close()
        b.close()


def test_plan_goes_around_the_other_robot(twins: CellThread) -> None:
    a, b = twins.client("a"), twins.client("b")
    try:
        for line in ("degrees", "guard on", "j 0,90,0,0,0,0,0", "motion follow", "speed 100"):
            assert a.ask(line) == "ok"
        reply = a.ask("j 180,90,0,0,0,0,0")  # the straight way swings through b
        assert re.fullmatch(r"error: link_\w+ would hit b/\w+ at \d+% of the move", reply)
        reply = a.ask("plan joints 180,90,0,0,0,0,0")
        assert re.fullmatch(r"ok \d+ waypoints \d+\.\d+ rad \d+\.\d+ s", reply), reply
        play = twins.call(lambda: twins.world.travel("a").path)
        model, other = twins.call(
            lambda: (twins.world.collision_model("a"), twins.world.others("a"))
        )
        times = np.arange(play.start, play.arrival, 0.005)
        path = [play.sample(t) for t in times]
        assert first_hit_between(model, twins.world.state("a").origin, other, path) is None
        assert a.ask("wait") == "ok" and a.ask("where") == "ok 180,90,0,0,0,0,0"
        assert b.ask("collisions") == "ok none"
    finally:
        a.close()
        b.close()


def test_another_robots_move_stops_a_guarded_move_in_its_way(twins: CellThread) -> None:
    """Issue 23.3 in a cell: b is put where a's running guarded move would end."""
    a, b, watcher = twins.client("a"), twins.client("b"), twins.client("a")
    try:
        for line in ("degrees", "j -90,90,0,0,0,0,0", "guard on", "motion on", "speed 10"):
            assert a.ask(line) == "ok"
        assert b.ask("degrees") == "ok" and watcher.ask("degrees") == "ok"
        a.send("j 0,90,0,0,0,0,0\n")
        for _ in range(100_000):  # until a has left its start
            if float(watcher.ask("where")[3:].split(",")[0]) > -89.9:
                break
        assert b.ask("j -60,90,0,0,0,0,0") == "ok"  # unguarded: at once, into a's way ahead
        reply = a.read_line()
        assert re.fullmatch(r"error: stopped: link_\w+ would hit b/\w+ \(b moved\)", reply), reply
        assert a.ask("collisions") == "ok none"
        reply = a.ask("j 0,90,0,0,0,0,0")
        assert re.fullmatch(r"error: link_\w+ would hit b/\w+ at \d+% of the move", reply), reply
    finally:
        a.close()
        b.close()
        watcher.close()
