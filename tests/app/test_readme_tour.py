"""The README's first commands run as written: the start-up lines, the piped client's
replies and exit status, and the five-minute tour, against the real program."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

from support import ROOT

README = (ROOT / "README.md").read_text()
CLI = Path(sys.executable).with_name("c2rviz-cli")


def block_after(marker: str) -> list[str]:
    """The lines of the first code block after ``marker``."""
    rest = README[README.index(marker) + len(marker) :]
    body = rest[rest.index("```") :].split("\n", 1)[1]
    return body[: body.index("```")].rstrip("\n").split("\n")


def run_cli(port: int, stdin: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [str(CLI), "--port", str(port)],
        input=stdin,
        capture_output=True,
        text=True,
        timeout=300,
    )


def test_the_start_up_lines_are_the_programs(c2rviz_process) -> None:
    proc = c2rviz_process("--crcl-port", "0", "--rosbridge-port", "0", "--viser-port", "0")
    shown = block_after("It prints where it listens and the browser address:")
    printed = "".join(proc.output)
    for line in shown:
        pattern = re.escape(line).replace(r"\ \.\.\.", ".*")
        pattern = re.sub(r"31000|64444|9090|8080", r"\\d+", pattern)
        assert re.search(pattern, printed), f"README: {line!r}\nprinted:\n{printed}"


def test_the_piped_client_prints_the_replies_shown(c2rviz_process) -> None:
    proc = c2rviz_process("--no-viewer", "--no-crcl")
    command = block_after("(one command per line on its input, each reply on its output):")
    (line,) = command
    lines = re.fullmatch(r"printf '(.*)' \| \.venv/bin/c2rviz-cli", line)
    assert lines is not None, line
    done = run_cli(proc.port, lines.group(1).encode().decode("unicode_escape"))
    shown = block_after(line + "\n```")
    assert done.stdout.splitlines() == [s for s in shown if not s.startswith("Socket ")]
    connected = [s for s in shown if s.startswith("Socket ")]
    assert [re.sub(r":\d+:", ":PORT:", s) for s in done.stderr.splitlines()] == [
        re.sub(r":\d+:", ":PORT:", s) for s in connected
    ]
    assert done.returncode == 1  # "It exits with status 1 because a line got an error."


def test_the_five_minute_tour_replies_as_shown(c2rviz_process) -> None:
    proc = c2rviz_process("--no-viewer", "--no-crcl")
    script = block_after("## A five-minute tour")
    assert script[0] == ".venv/bin/c2rviz-cli <<'EOF'" and script[-1] == "EOF"
    done = run_cli(proc.port, "\n".join(script[1:-1]) + "\n")
    assert done.stdout.splitlines() == block_after("\nEOF\n```"), done.stderr


def test_a_recording_and_its_bag_played_back(c2rviz_process, tmp_path) -> None:
    proc = c2rviz_process("--no-viewer", "--no-crcl", "--record-dir", str(tmp_path))
    marker = "Record a session; the recording is a command file, a CSV, a page and a ROS bag:"
    (line,) = block_after(marker)
    lines = re.fullmatch(r"printf '(.*)' \| \.venv/bin/c2rviz-cli", line)
    assert lines is not None, line
    done = run_cli(proc.port, lines.group(1).encode().decode("unicode_escape"))

    def shape(text: str, folder: str) -> str:  # the folder and the figures vary
        return re.sub(r"\d+(\.\d+)?", "#", text.replace(folder, "FOLDER"))

    shown = block_after(line + "\n```")
    assert [shape(s, str(tmp_path)) for s in done.stdout.splitlines()] == [
        shape(s, "/home/you/c2rviz/recordings") for s in shown
    ]
    assert (tmp_path / "demo" / "demo.mcap").is_file()
    play = Path(sys.executable).with_name("c2rviz-play")
    played = subprocess.run(
        [str(play), str(tmp_path / "demo"), "--port", str(proc.port)],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert played.returncode == 0 and "/joint_states, all ok" in played.stdout, played


def test_the_client_example_runs_against_the_server(c2rviz_process) -> None:
    proc = c2rviz_process("--no-viewer", "--no-crcl")
    snippet = "\n".join(block_after("an `error:` raises `CommandError`):"))
    assert "port=31000" in snippet
    done = subprocess.run(
        [sys.executable, "-c", snippet.replace("port=31000", f"port={proc.port}")],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith("(0.5, 0.2, 0.0, -0.4, 0.0, 0.3, 0.0) Pose(x="), done.stdout


def test_the_pytest_example_passes_with_the_plugin(tmp_path) -> None:
    snippet = block_after("`c2rviz --clock virtual`\nfor a whole program, or `--clock scaled:10`):")
    (tmp_path / "test_readme.py").write_text("\n".join(snippet) + "\n")
    done = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "test_readme.py"],  # the plugin: by entry point
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0 and "1 passed" in done.stdout, done.stdout + done.stderr
