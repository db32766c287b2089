"""Every file in commands/ parses, says what it shows, and plays all-ok on its robot."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from support import ROBOTS, ROOT

from c2rviz.clients import player
from c2rviz.protocol.grammar import parse_line

COMMANDS_DIR = ROOT / "commands"
FILES = sorted(COMMANDS_DIR.glob("*.txt"))
IDS = [path.name for path in FILES]

# The seed's `file motoman.txt` listing ("subtokens ..."), one command per line.
SEED_MOTOMAN = [
    "sleep 5", "degrees", "home", "rand", "sleep 5", "move 0 90.0", "sleep 3",
    "move 0 -90.0", "sleep 3", "j 45,45,45,45,45,45,45", "sleep 3",
    "joints 0,0,0,0,0,0,0", "sleep 3", "move 0,1 90,90", "sleep 4.0", "move 0,1 -90,-90",
]  # fmt: skip


def header(path: Path) -> str:
    """The comment block the file opens with."""
    lines = path.read_text().splitlines()
    block = []
    for line in lines:
        if not line.startswith("#"):
            break
        block.append(line)
    return "\n".join(block)


def robot_of(path: Path) -> str:
    """The robot the file declares (``# robot: NAME``), the one it says to start."""
    declared = player.load_script(path).robot
    assert declared, f"{path.name} has no '# robot: NAME' line"
    match = re.search(r"c2rviz --robot (\w+)", header(path))
    assert match, f"{path.name} does not say how to start its robot (`c2rviz --robot NAME`)"
    assert match.group(1) == declared, path.name
    return declared


def command_lines(path: Path) -> list[str]:
    return [
        line.split("#", 1)[0].strip()
        for line in path.read_text().splitlines()
        if line.split("#", 1)[0].strip()
    ]


def test_there_is_a_demo_for_every_bundled_robot():
    assert {robot_of(path) for path in FILES} >= set(ROBOTS)


@pytest.mark.parametrize("path", FILES, ids=IDS)
def test_every_line_parses(path):
    commands = [parse_line(line) for line in path.read_text().splitlines()]
    assert any(command is not None for command in commands)


@pytest.mark.parametrize("path", FILES, ids=IDS)
def test_the_file_opens_with_a_comment_naming_its_robot(path):
    assert len(header(path).splitlines()) >= 2, f"{path.name}: say what the file shows"
    assert robot_of(path) in ROBOTS


@pytest.mark.parametrize("path", FILES, ids=IDS)
def test_the_file_plays_all_ok_on_its_robot(path, start_server, capsys):
    server = start_server(robot_of(path))
    assert player.main([str(path), "--port", str(server.port), "--speed", "1000"]) == 0
    out = capsys.readouterr().out
    played = [line for line in out.splitlines() if line.startswith("[")]
    assert len(played) == len(command_lines(path))
    assert all(" -> ok" in line for line in played)


def test_motoman_txt_is_the_seeds_script():
    assert command_lines(COMMANDS_DIR / "motoman.txt") == SEED_MOTOMAN
    assert robot_of(COMMANDS_DIR / "motoman.txt") == "motoman_sia20d"
