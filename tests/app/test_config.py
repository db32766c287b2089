"""cmdinterpreter.ini and the flags that override it; every bad value exits 2."""

from __future__ import annotations

import shutil
import socket

import pytest
from support import ROOT, Client

from c2rviz.app.cli import main
from c2rviz.app.config import ServerLimits, load_settings
from c2rviz.errors import ConfigError
from c2rviz.ini import find_ini
from c2rviz.robot.sources import load_source

INI = ROOT / "cmdinterpreter.ini"


def test_the_shipped_ini_names_the_seed_robots():
    settings = load_settings(INI, {})
    assert (settings.host, settings.port, settings.hz) == ("127.0.0.1", 31000, 100.0)
    assert (settings.viewer_host, settings.viewer_port) == ("127.0.0.1", 8080)
    assert set(settings.robots) == {"motoman_sia20d", "fanuc_lrmate200id", "kuka_lwr"}
    assert settings.urdf == ROOT / "robots/motoman_sia20d/robot.urdf"
    assert (settings.base, settings.eelink) == ("base_link", "link_t")
    assert settings.limits == ServerLimits()


def test_flags_override_the_file():
    settings = load_settings(
        INI, {"robot": "kuka_lwr", "port": 0, "eelink": "lwr_6_link", "max_clients": 3}
    )
    assert settings.urdf == ROOT / "robots/kuka_lwr/robot.urdf"
    assert (settings.base, settings.eelink) == ("lwr_base_link", "lwr_6_link")
    assert settings.port == 0
    assert settings.limits.max_clients == 3


def test_urdf_flag_with_a_robot_section_keeps_its_links(tmp_path):
    settings = load_settings(INI, {"robot": "fanuc_lrmate200id", "urdf": tmp_path / "x.urdf"})
    assert (settings.base, settings.eelink) == ("base_link", "link_6")
    alone = load_settings(INI, {"urdf": tmp_path / "x.urdf"})
    assert (alone.base, alone.eelink) == (None, None)


def test_relative_urdf_paths_are_relative_to_the_ini(tmp_path):
    ini = tmp_path / "my.ini"
    ini.write_text("[options]\nrobot = arm\n[arm]\nurdf = urdf/arm.urdf\neelink = tip\n")
    settings = load_settings(ini, {})
    assert settings.urdf == tmp_path / "urdf" / "arm.urdf"
    assert settings.eelink == "tip"


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("[options]\nport = lots\n", "[options] port = 'lots' is not a whole number"),
        ("[options]\nport = 70000\n", "[options] port = 70000 is outside 0..65535"),
        ("[options]\nhz = 0\n", "[options] hz = 0 is outside 1..1000"),
        ("[options]\ncolour = red\n", "unknown key 'colour' in [options]"),
        ("[arm]\nbase = a\n", "[arm] of"),
        ("[arm]\nurdf = a.urdf\ntip = x\n", "unknown key 'tip' in [arm]"),
        ("no section\n", "cannot read"),
    ],
    ids=["port-text", "port-range", "hz-zero", "unknown-option", "no-urdf", "robot-key", "junk"],
)
def test_bad_ini_values_are_named(tmp_path, text, message):
    ini = tmp_path / "bad.ini"
    ini.write_text(text)
    with pytest.raises(ConfigError) as info:
        load_settings(ini, {"urdf": tmp_path / "x.urdf"})
    assert message in str(info.value)


def test_find_ini_prefers_the_flag_then_the_working_directory(tmp_path, monkeypatch):
    with pytest.raises(ConfigError, match="does not exist"):
        find_ini(tmp_path / "missing.ini")
    monkeypatch.chdir(tmp_path)
    assert find_ini(None) == INI  # falls back to the project's
    (tmp_path / "cmdinterpreter.ini").write_text("[options]\n")
    assert find_ini(None) == tmp_path / "cmdinterpreter.ini"


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--robot", "r2d2"], "unknown robot 'r2d2'"),
        (
            ["--urdf", "/nonexistent/robot.urdf"],
            "URDF file '/nonexistent/robot.urdf' does not exist",
        ),
        (["--config", "/nonexistent.ini"], "config file '/nonexistent.ini' does not exist"),
        (["--port", "99999"], "--port 99999 is outside 0..65535"),
        (["--eelink", "hand"], "eelink link 'hand' is not in motoman_sia20d"),
        (["--robot", "fanuc_lrmate200id", "--base", "link_2", "--eelink", "link_1"], "below base"),
    ],
    ids=["robot", "urdf", "config", "port", "eelink", "chain"],
)
def test_main_exits_2_with_one_clear_sentence(argv, message, capsys):
    assert main([*argv, "--no-viewer"]) == 2
    err = capsys.readouterr().err.strip()
    assert message in err
    assert err.count("\n") == 0, err
    if argv == ["--robot", "r2d2"]:
        assert "choose from: fanuc_lrmate200id, kuka_lwr, motoman_sia20d" in err


def test_a_taken_command_port_is_the_one_thing_said(capsys, caplog):
    """Both ports taken (a second c2rviz): one sentence on the command port, exit 2, and
    nothing from the viewer (it once said first that it had moved to the next port)."""
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        assert main(["--port", str(port), "--viser-port", str(port)]) == 2
    out, err = capsys.readouterr()
    assert out == ""
    assert caplog.records == []  # the viewer never started, so it had nothing to say
    assert err == (
        f"c2rviz: cannot listen for commands on 127.0.0.1:{port}: the port is in use "
        "(another c2rviz?); choose another with --port (0 picks a free one)\n"
    )


@pytest.mark.parametrize("how", ["flag", "ini"])
def test_a_taken_viewer_port_that_was_named_stops_the_program(how, tmp_path, capsys):
    """Issue 39, fault 12: a named --viser-port that is taken stops the program with status
    2 and one sentence, as every other door's named port does; it once moved to the next."""
    doors = ["--port", "0", "--crcl-port", "0", "--rosbridge-port", "0"]
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        if how == "flag":
            argv = [*doors, "--viser-port", str(port)]
        else:
            ini = tmp_path / "cmdinterpreter.ini"
            ini.write_text(f"[options]\nviewer_port = {port}\n")
            argv = [*doors, "--config", str(ini)]
        assert main(argv) == 2
    out, err = capsys.readouterr()
    assert out == ""
    assert err == (
        f"c2rviz: cannot serve the viewer on 127.0.0.1:{port}: the port is in use; choose "
        "another with --viser-port (0 picks a free one)\n"
    )


def test_port_zero_prints_the_port_it_picked(c2rviz_process):
    proc = c2rviz_process("--no-viewer")
    assert proc.port > 0
    assert any(f"commands on 127.0.0.1:{proc.port}" in line for line in proc.output)


def test_the_robot_goes_by_the_name_the_user_chose(c2rviz_process):
    """--robot kuka_lwr (whose URDF says lwr): kuka_lwr in the banner, names and errors."""
    proc = c2rviz_process("--robot", "kuka_lwr", "--no-viewer")
    banner = next(line for line in proc.output if "chain" in line)
    assert banner.startswith("c2rviz: kuka_lwr (model lwr), chain lwr_base_link -> lwr_7_link,")
    client = Client("127.0.0.1", proc.port)
    try:
        joints = ",".join(f"lwr_{i}_joint" for i in range(7))
        assert client.ask("names") == f"ok kuka_lwr {joints}"
        assert client.ask("move 9 1") == (
            "error: joint index 9 out of range: kuka_lwr has joints 0..6"
        )
        assert client.ask("quit") == "ok"
    finally:
        client.close()
    assert proc.wait() == 0


TINY_WS = ROOT / "tests" / "data" / "tiny_ws"
FINGER_URI = "package://tiny_gripper/meshes/finger.stl"


@pytest.mark.parametrize(
    "entry",
    ["tiny_gripper=../ws/src/gripper-checkout", "../ws", "../ws/src/gripper-checkout"],
    ids=["name=dir", "workspace", "the-package-itself"],
)
def test_ini_package_path_takes_the_flags_forms_relative_to_the_ini(tmp_path, monkeypatch, entry):
    shutil.copytree(TINY_WS, tmp_path / "ws")
    ini = tmp_path / "cfg" / "my.ini"
    ini.parent.mkdir()
    ini.write_text(
        f"[tiny]\nurdf = ../ws/src/tiny_description/urdf/tiny.urdf\npackage_path = {entry}\n"
    )
    monkeypatch.chdir(tmp_path / "ws")  # relative to the ini, not to here
    settings = load_settings(ini, {"robot": "tiny"})
    assert settings.urdf is not None
    source = load_source(settings.urdf, settings.package_paths, environ={})
    assert source.resolve(FINGER_URI) == tmp_path / "ws/src/gripper-checkout/meshes/finger.stl"


@pytest.mark.parametrize(
    ("entry", "folder", "named"),
    [
        ("kuka_kr6_support=../nope", "nope", " (for package kuka_kr6_support)"),
        ("nope", "cfg/nope", ""),
    ],
    ids=["name=dir", "dir"],
)
def test_a_missing_ini_package_path_names_the_ini_key(tmp_path, capsys, entry, folder, named):
    ini = tmp_path / "cfg" / "my.ini"
    ini.parent.mkdir()
    urdf = INI.parent / "robots/kuka_lwr/robot.urdf"
    ini.write_text(
        f"[options]\nrobot = kr6\n[kr6]\nurdf = {urdf}\npackage_path = {entry}\n"
        f"[lwr]\nurdf = {urdf}\n"
    )
    expected = (
        f"[kr6] package_path in {ini}: {str(tmp_path / folder)!r}{named} is not a folder "
        "(entries are DIR or NAME=DIR, relative to the ini file)"
    )
    with pytest.raises(ConfigError) as info:
        load_settings(ini, {})
    assert str(info.value) == expected
    assert load_settings(ini, {"robot": "lwr"}).urdf == urdf  # only the chosen one counts
    assert main(["--config", str(ini), "--no-viewer"]) == 2
    err = capsys.readouterr().err
    assert err == f"c2rviz: {expected}\n" and "--package-path" not in err


def test_the_viewers_door_settings_come_from_the_ini_and_the_flags(tmp_path):
    ini = tmp_path / "door.ini"
    ini.write_text(
        "[options]\nviewer_origins = https://a.example http://b.example:8080\n"
        "viewer_token = abc\nmax_viewers = 3\n"
    )
    settings = load_settings(ini, {"urdf": tmp_path / "x.urdf"})
    assert settings.viewer_origins == ("https://a.example", "http://b.example:8080")
    assert settings.viewer_token == "abc" and settings.max_viewers == 3
    flags = {"urdf": tmp_path / "x.urdf", "viewer_origins": ["https://c.example"]}
    assert load_settings(ini, {**flags, "max_viewers": 5}).viewer_origins == ("https://c.example",)
    with pytest.raises(ConfigError, match="--max-viewers 0 is outside 1..1024"):
        load_settings(ini, {**flags, "max_viewers": 0})
    ini.write_text("[options]\nmax_viewers = 2000\n")
    with pytest.raises(ConfigError, match=r"\[options\] max_viewers = 2000 is outside 1..1024"):
        load_settings(ini, {"urdf": tmp_path / "x.urdf"})


def test_the_pages_lighting_comes_from_the_ini_and_the_flag(tmp_path):
    ini = tmp_path / "light.ini"
    ini.write_text("[options]\nviewer_lighting = plain\n")
    urdf = {"urdf": tmp_path / "x.urdf"}
    assert load_settings(None, urdf).viewer_lighting == "studio"
    assert load_settings(ini, urdf).viewer_lighting == "plain"
    assert load_settings(ini, {**urdf, "viewer_lighting": "studio"}).viewer_lighting == "studio"
    ini.write_text("[options]\nviewer_lighting = dim\n")
    with pytest.raises(ConfigError, match=r"viewer_lighting = 'dim' is not one.*studio, plain"):
        load_settings(ini, urdf)


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--viewer-origin", "evil"], "viewer origin 'evil' is not scheme://host[:port]"),
        (["--viewer-token", "t\u00e9"], "is not printable ASCII"),
    ],
    ids=["origin", "token"],
)
def test_a_bad_door_setting_exits_2_with_one_sentence(argv, message, capsys):
    doors = ["--crcl-port", "0", "--rosbridge-port", "0"]  # free ports: no note of a busy one
    assert main([*argv, *doors, "--viser-port", "0", "--port", "0"]) == 2
    err = capsys.readouterr().err.strip()
    assert message in err and err.count("\n") == 0, err


def session_settings(port: int) -> dict[str, str]:
    """What a new connection starts with: motion, speed, guard and lspeed replies."""
    sock = socket.create_connection(("127.0.0.1", port), timeout=30)
    with sock, sock.makefile("rb") as replies_in:
        answers = {}
        for verb in ("motion", "speed", "guard", "lspeed"):
            sock.sendall(f"{verb}\n".encode())
            answers[verb] = replies_in.readline().decode().strip()
        return answers


def test_session_defaults_and_workcell_limits_from_the_ini_and_from_flags(tmp_path, c2rviz_process):
    """motion, speed, guard, lspeed and max_objects from [options]; the flags win; --srdf
    turns pairs off. Read back over the command port, as a controller would."""
    ini = tmp_path / "c2rviz.ini"  # the shipped file, its defaults changed
    text = (ROOT / "cmdinterpreter.ini").read_text().replace("= robots/", f"= {ROOT}/robots/")
    for default, value in (
        ("motion = off", "motion = on"),
        ("speed = 50", "speed = 30"),
        ("guard = off", "guard = on"),
        ("lspeed = 0.25", "lspeed = 0.1"),
        ("max_objects = 100", "max_objects = 2"),
    ):
        assert f"\n{default}\n" in text, default
        text = text.replace(f"\n{default}\n", f"\n{value}\n", 1)
    ini.write_text(text)
    proc = c2rviz_process("--config", str(ini), "--no-viewer")
    assert session_settings(proc.port) == {
        "motion": "ok on",
        "speed": "ok 30",
        "guard": "ok on",
        "lspeed": "ok 0.1",
    }
    client = Client("127.0.0.1", proc.port)
    try:
        assert client.ask("object a sphere 0.05 2,0,0") == "ok"
        assert client.ask("object b sphere 0.05 2,1,0") == "ok"
        assert client.ask("object c sphere 0.05 2,2,0").startswith("error: ")  # 2 at most
    finally:
        client.close()
    srdf = ROOT / "tests" / "data" / "collision" / "motoman.srdf"
    flags = ("--motion", "follow", "--speed", "70", "--guard", "off", "--srdf", str(srdf))
    other = c2rviz_process("--config", str(ini), "--no-viewer", *flags)
    assert session_settings(other.port) == {
        "motion": "ok follow",
        "speed": "ok 70",
        "guard": "ok off",
        "lspeed": "ok 0.1",
    }
    client = Client("127.0.0.1", other.port)
    try:
        for line in ("motion off", "degrees", "j 0,-106,0,122,0,0,0"):  # folded onto its base
            assert client.ask(line) == "ok"
        assert client.ask("collisions") == "ok base_link~link_u"  # the SRDF's pairs are off
    finally:
        client.close()


@pytest.mark.parametrize("what", ["config", "cell"])
def test_a_stray_byte_in_an_ini_or_cell_file_is_one_sentence(tmp_path, capsys, what):
    """Issue 23.10: a 0xFF byte was a traceback and exit 1; it is exit 2 and one sentence."""
    bad = tmp_path / "bad.ini"
    bad.write_bytes(b"[options]\nport = 31000\n# \xff\n")
    flag = "--config" if what == "config" else "--cell"
    assert main([flag, str(bad), "--no-viewer"]) == 2
    err = capsys.readouterr().err
    assert (
        err.startswith(f"c2rviz: cannot read {bad}: byte 0xff at offset ") and err.count("\n") == 1
    )
    assert "is not UTF-8 text" in err
