"""The program's rosbridge door: its flags, its ini key, its port rule, a cell's namespaces.

These start ``python -m c2rviz`` and talk to it with roslibpy (asyncio transport),
as a ROS script would.
"""

from __future__ import annotations

import errno
import os
import re
import socket
import subprocess
import sys
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest
import roslibpy
from roslibpy.ros import set_rosapi_timeout
from support import ROOT, Process

from c2rviz.app.config import load_settings
from c2rviz.app.doors import DEFAULT_ROSBRIDGE_PORT
from c2rviz.errors import ConfigError

WAIT_S = 60.0


def read_until(proc: Process, pattern: str) -> re.Match[str]:
    """Read the program's output until a line matches ``pattern``."""
    assert proc.popen.stdout is not None
    while True:
        line = proc.popen.stdout.readline()
        assert line, "c2rviz stopped:\n" + "".join(proc.output)
        proc.output.append(line)
        if found := re.search(pattern, line):
            return found


@pytest.fixture
def ros_at() -> Iterator[Callable[[int], roslibpy.Ros]]:
    opened: list[roslibpy.Ros] = []

    def connect(port: int) -> roslibpy.Ros:
        set_rosapi_timeout(WAIT_S)
        client = roslibpy.Ros("127.0.0.1", port, transport="asyncio")
        client.run(timeout=WAIT_S)
        opened.append(client)
        return client

    yield connect
    for client in opened:
        client.close()


def test_the_door_opens_beside_the_text_port(c2rviz_process, ros_at) -> None:
    proc = c2rviz_process("--no-viewer", "--rosbridge-port", "0")
    port = int(read_until(proc, r"c2rviz: rosbridge at ws://127\.0\.0\.1:(\d+)/ \(")[1])
    ros = ros_at(port)
    assert "/joint_states" in ros.get_topics()
    service = roslibpy.Service(ros, "/c2rviz/command", "c2rviz_msgs/srv/Command")
    request = roslibpy.ServiceRequest({"command": "joints 0.1,0,0,0,0,0,0"})
    answer = service.call(request, timeout=WAIT_S)
    assert answer == {"reply": "ok", "ok": True}
    with socket.create_connection(("127.0.0.1", proc.port), timeout=WAIT_S) as text:
        text.sendall(b"where\nquit\n")
        assert text.makefile().readline() == "ok 0.1,0,0,0,0,0,0\n"
    assert proc.wait(WAIT_S) == 0


def test_no_rosbridge_opens_no_door(c2rviz_process) -> None:
    proc = c2rviz_process("--no-viewer", "--rosbridge-port", "0", "--no-rosbridge")
    with socket.create_connection(("127.0.0.1", proc.port), timeout=WAIT_S) as text:
        text.sendall(b"quit\n")
        assert text.makefile().readline() == "ok\n"
    assert proc.wait(WAIT_S) == 0
    assert proc.popen.stdout is not None
    rest = proc.popen.stdout.read()
    assert "rosbridge" not in "".join(proc.output) + rest


def _hold(port: int) -> socket.socket | None:
    """Listen on ``port`` unless something else does already (then it is taken anyway)."""
    holder = socket.socket()
    try:
        holder.bind(("127.0.0.1", port))
    except OSError as exc:
        holder.close()
        assert exc.errno == errno.EADDRINUSE
        return None
    holder.listen()
    return holder


@pytest.mark.xdist_group("default_ports")  # binds a default port: one at a time
def test_a_taken_default_port_costs_only_the_door() -> None:
    holder = _hold(DEFAULT_ROSBRIDGE_PORT)
    proc = subprocess.Popen(
        [sys.executable, "-m", "c2rviz", "--no-viewer", "--port", "0"],
        cwd=ROOT,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        env={**os.environ, "PYTHONUNBUFFERED": "1"},
    )
    try:
        assert proc.stdout is not None
        lines = []
        while not any("commands on" in line for line in lines):
            lines.append(proc.stdout.readline())
            assert lines[-1], "".join(lines)
        assert (
            "c2rviz: rosbridge port 9090 is in use (another c2rviz?): no rosbridge door this "
            "time (--rosbridge-port N chooses another, 0 a free one)\n"
        ) in lines
        port = int(re.findall(r"commands on [\d.]+:(\d+)", "".join(lines))[0])
        with socket.create_connection(("127.0.0.1", port), timeout=WAIT_S) as text:
            text.sendall(b"where\nquit\n")
            assert text.makefile().readline().startswith("ok 0,")
        assert proc.wait(WAIT_S) == 0
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait(WAIT_S)
        if proc.stdout is not None:
            proc.stdout.close()
        if holder is not None:
            holder.close()


def test_a_taken_named_port_stops_the_program() -> None:
    with socket.socket() as holder:
        holder.bind(("127.0.0.1", 0))
        holder.listen()
        port = holder.getsockname()[1]
        done = subprocess.run(
            [sys.executable, "-m", "c2rviz", "--no-viewer", "--port", "0"]
            + ["--rosbridge-port", str(port)],
            cwd=ROOT,
            capture_output=True,
            text=True,
            timeout=WAIT_S,
        )
    assert done.returncode == 2
    assert (
        f"cannot listen for rosbridge on 127.0.0.1:{port}: the port is in use; choose another "
        "with --rosbridge-port (0 picks a free one)"
    ) in done.stderr


def test_the_ini_names_the_port(tmp_path: Path) -> None:
    ini = tmp_path / "c.ini"
    ini.write_text("[options]\nrosbridge_port = 9191\n" + ROBOTS_INI.format(root=ROOT))
    assert load_settings(ini, {}).rosbridge_port == 9191
    assert load_settings(ini, {"rosbridge_port": 0}).rosbridge_port == 0  # the flag wins
    plain = tmp_path / "plain.ini"
    plain.write_text(ROBOTS_INI.format(root=ROOT))
    assert load_settings(plain, {}).rosbridge_port is None  # the default, not named
    ini.write_text("[options]\nrosbridge_port = 70000\n" + ROBOTS_INI.format(root=ROOT))
    with pytest.raises(ConfigError, match="rosbridge_port"):
        load_settings(ini, {})
    with pytest.raises(ConfigError, match="--rosbridge-port 70000 is outside 0..65535"):
        load_settings(plain, {"rosbridge_port": 70000})


ROBOTS_INI = """
[motoman_sia20d]
base = base_link
eelink = link_t
urdf = {root}/robots/motoman_sia20d/robot.urdf

[fanuc_lrmate200id]
base = base_link
eelink = link_6
urdf = {root}/robots/fanuc_lrmate200id/robot.urdf
"""

CELL_INI = (
    ROBOTS_INI
    + """
[cell:pair]
robots = left right

[left]
robot = motoman_sia20d
origin = 0,0,0,0,0,0
port = 0

[right]
robot = fanuc_lrmate200id
origin = 1.2,0,0,0,0,180
port = 0
"""
)


def test_a_cell_is_served_under_namespaces(c2rviz_process, ros_at, tmp_path: Path) -> None:
    ini = tmp_path / "cell.ini"
    ini.write_text(CELL_INI.format(root=ROOT))
    proc = c2rviz_process("--cell", str(ini), "--no-viewer", "--rosbridge-port", "0")
    found = read_until(proc, r"rosbridge at ws://127\.0\.0\.1:(\d+)/ \(robots under /left, /right")
    ros = ros_at(int(found[1]))
    topics = ros.get_topics()
    assert {"/left/joint_states", "/right/joint_states", "/tf", "/tf_static"} <= set(topics)
    service = roslibpy.Service(ros, "/right/c2rviz/command", "c2rviz_msgs/srv/Command")
    answer = service.call(roslibpy.ServiceRequest({"command": "robot"}), timeout=WAIT_S)
    assert answer == {"reply": "ok right", "ok": True}
