"""The CRCL door in the program: its flags, the ini key, the port rule, a cell's ports,
and a CRCL program played against the running program by ``c2rviz-play``."""

from __future__ import annotations

import asyncio
import re
import socket
import subprocess
import sys

import pytest
from crcl_support import DONE, CrclClient, command
from support import ROOT, Process, load_robot

from c2rviz.app.config import Settings, load_settings
from c2rviz.app.doors import OPENERS, close_doors, open_crcl
from c2rviz.app.members import Member
from c2rviz.errors import ConfigError
from c2rviz.motion.limits import motion_limits
from c2rviz.session import Services
from c2rviz.transports.crcl.server import DEFAULT_PORT
from c2rviz.world.world import World


def crcl_port(proc: Process, who: str = "") -> int:
    """The CRCL port the program's banner gives (reading on until it says it)."""
    pattern = re.compile(rf"{who}CRCL on 127\.0\.0\.1:(\d+) \(docs/crcl\.md\)")
    lines = iter(proc.output)
    while True:
        line = next(lines, None)
        if line is None:
            assert proc.popen.stdout is not None
            line = proc.popen.stdout.readline()
            if not line:
                raise AssertionError("no CRCL line in:\n" + "".join(proc.output))
            proc.output.append(line)
        if found := pattern.search(line):
            return int(found.group(1))


def test_the_program_opens_a_crcl_door_that_drives_its_robot(c2rviz_process, tmp_path) -> None:
    proc = c2rviz_process("--no-viewer", "--crcl-port", "0", "--robot", "fanuc_lrmate200id")
    port = crcl_port(proc)
    client = CrclClient("127.0.0.1", port)
    try:
        assert client.run(command("InitCanon", 1), 1).command_status.state == DONE
        status = client.ask(2)
        assert len(status.joint_statuses.statuses) == 6
        assert status.gripper_status.gripper_name == "gripper_hand"
    finally:
        client.close()
    program = tmp_path / "grip.xml"
    program.write_text(
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        '<CRCLProgram xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance">\n'
        "  <InitCanon><CommandID>1</CommandID></InitCanon>\n"
        '  <MiddleCommand xsi:type="SetEndEffectorType">\n'
        "    <CommandID>2</CommandID> <Setting>1</Setting>\n  </MiddleCommand>\n"
        "  <EndCanon><CommandID>3</CommandID></EndCanon>\n</CRCLProgram>\n"
    )
    played = subprocess.run(
        [sys.executable, "-m", "c2rviz.clients.player", str(program), "--port", str(port)],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert played.returncode == 0, played.stderr
    assert "[1/2] SetEndEffectorType (CommandID 2): done" in played.stdout
    proc.popen.terminate()
    assert proc.wait() == 0


def test_no_crcl_opens_none(c2rviz_process) -> None:
    proc = c2rviz_process("--no-viewer", "--no-crcl")
    assert not any("CRCL" in line for line in proc.output)
    proc.popen.terminate()
    assert proc.wait() == 0


@pytest.mark.xdist_group("default_ports")  # binds a default port: one at a time
def test_a_taken_default_port_costs_only_the_crcl_door(c2rviz_process) -> None:
    with socket.socket() as holder:
        holder.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            holder.bind(("127.0.0.1", DEFAULT_PORT))
            holder.listen()
        except OSError:
            pass  # something else holds it already: as good
        proc = c2rviz_process("--no-viewer", default_crcl_port=True)
        said = "".join(proc.output)
        assert (
            f"c2rviz: CRCL port {DEFAULT_PORT} is in use (another c2rviz?): no CRCL door this "
            "time (--crcl-port N chooses another, 0 a free one)"
        ) in said
        assert "commands on 127.0.0.1:" in said
        proc.popen.terminate()
        assert proc.wait() == 0


def test_a_taken_named_port_stops_the_program() -> None:
    with socket.socket() as holder:
        holder.bind(("127.0.0.1", 0))
        holder.listen()
        port = holder.getsockname()[1]
        done = subprocess.run(
            [
                sys.executable,
                "-m",
                "c2rviz",
                "--no-viewer",
                "--port",
                "0",
                "--crcl-port",
                str(port),
            ],
            cwd=ROOT,
            capture_output=True,
            text=True,
            timeout=120,
        )
    assert done.returncode == 2
    assert f"cannot listen for CRCL on 127.0.0.1:{port}: the port is in use" in done.stderr


def test_a_cell_gives_each_robot_its_own_crcl_port(c2rviz_process) -> None:
    proc = c2rviz_process("--no-viewer", "--cell", "twoarms", "--crcl-port", "0")
    left, right = crcl_port(proc, "left: "), crcl_port(proc, "right: ")
    assert left != right
    for port, joints in ((left, 7), (right, 6)):
        client = CrclClient("127.0.0.1", port)
        try:
            assert len(client.ask(1).joint_statuses.statuses) == joints
        finally:
            client.close()
    proc.popen.terminate()
    assert proc.wait() == 0


def test_the_ini_key_and_the_flag(tmp_path) -> None:
    ini = tmp_path / "c.ini"
    ini.write_text("[options]\ncrcl_port = 7000\n")
    urdf = {"urdf": ROOT / "robots" / "kuka_lwr" / "robot.urdf"}
    assert load_settings(ini, urdf).crcl_port == 7000
    assert load_settings(ini, {**urdf, "crcl_port": 7001}).crcl_port == 7001
    assert load_settings(None, urdf).crcl_port is None  # the default, not named
    assert load_settings(None, {**urdf, "crcl": False}).crcl is False
    ini.write_text("[options]\ncrcl_port = 70000\n")
    with pytest.raises(ConfigError, match="crcl_port = 70000 is outside 0..65535"):
        load_settings(ini, urdf)
    assert open_crcl in OPENERS


def test_consecutive_ports_from_the_base(tmp_path) -> None:
    robot = load_robot()
    members = [
        Member(name, robot, __import__("pinocchio").SE3.Identity(), 0, motion_limits(robot))
        for name in ("a", "b")
    ]

    async def open_them(base: int) -> list[int]:
        world = World({m.name: m.robot for m in members})
        services = Services(world)
        settings = Settings(crcl_port=base)
        opened = await open_crcl(settings, services, members, lambda: None)
        try:
            return [int(entry.banner.split(":")[-1].split()[0]) for entry in opened]
        finally:
            await close_doors(opened)
            services.close()

    with pytest.raises(ConfigError, match="leaves no room for 2 robots' CRCL ports"):
        asyncio.run(open_them(65535))
    base = _two_free_ports()
    assert asyncio.run(open_them(base)) == [base, base + 1]


def _two_free_ports() -> int:
    for _ in range(50):
        with socket.socket() as first:
            first.bind(("127.0.0.1", 0))
            port = first.getsockname()[1]
        if port >= 65535:
            continue
        with socket.socket() as second:
            try:
                second.bind(("127.0.0.1", port + 1))
            except OSError:
                continue
        return port
    raise AssertionError("no two free ports in a row")
