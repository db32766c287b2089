"""The README's first commands run as written: the start-up lines, the piped client's
replies and exit status, and the five-minute tour, against the real program."""

from __future__ import annotations

import contextlib
import os
import re
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

from support import ROOT
from viewer_tabs import Tab

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


def test_the_plain_lighting_line_starts_a_page_lit_plainly(c2rviz_process) -> None:
    """The page's first message of lighting turns viser's environment map off (with the
    default lighting, studio, none is sent)."""
    (line,) = block_after("draws the\nrobot with a third of the CPU")
    program, *args = line.split()
    assert program == ".venv/bin/c2rviz", line
    proc = c2rviz_process(*args, "--viser-port", "0")
    tab = Tab(proc.viewer_url)
    try:
        kinds = ("EnvironmentMapMessage",)
        tab.wait(lambda: any(m["type"] in kinds for m in tab.received), "the lighting")
        (lighting,) = [m for m in tab.received if m["type"] in kinds]
        assert lighting["hdri_data"] is None
    finally:
        tab.close()


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


@contextlib.contextmanager
def program_in(folder: Path, *args: str) -> Iterator[int]:
    """``c2rviz --port 0 ARGS`` started in ``folder`` (so ./recordings is there); its port."""
    popen = subprocess.Popen(
        [sys.executable, "-m", "c2rviz", "--port", "0", *args],
        cwd=folder,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        env={**os.environ, "PYTHONUNBUFFERED": "1"},
    )
    try:
        assert popen.stdout is not None
        seen = []
        while not (m := re.search(r"commands on [\d.]+:(\d+)", seen[-1] if seen else "")):
            seen.append(popen.stdout.readline())
            assert seen[-1], "c2rviz did not start:\n" + "".join(seen)
        yield int(m.group(1))
    finally:
        popen.terminate()
        popen.communicate(timeout=60)


def test_a_recording_and_its_bag_played_back(tmp_path) -> None:
    """As the README has it: the program started in a folder records into its
    ``recordings/``; ``record`` says that folder in full, ``record stop`` names the files
    as the program sees them (issue 39, rough edge 10: it showed them in full)."""
    with program_in(tmp_path, "--no-viewer", "--no-crcl", "--no-rosbridge") as port:
        marker = "Record a session; the recording is a command file, a CSV, a page and a ROS bag:"
        (line,) = block_after(marker)
        lines = re.fullmatch(r"printf '(.*)' \| \.venv/bin/c2rviz-cli", line)
        assert lines is not None, line
        done = run_cli(port, lines.group(1).encode().decode("unicode_escape"))

        def shape(text: str, folder: str) -> str:  # the folder and the figures vary
            return re.sub(r"\d+(\.\d+)?", "#", text.replace(folder, "FOLDER"))

        shown = block_after(line + "\n```")
        folder = str((tmp_path / "recordings").resolve())
        assert [shape(s, folder) for s in done.stdout.splitlines()] == [
            shape(s, "/home/you/c2rviz/recordings") for s in shown
        ]
        assert (tmp_path / "recordings" / "demo" / "demo.mcap").is_file()
        play = Path(sys.executable).with_name("c2rviz-play")
        played = subprocess.run(
            [str(play), "recordings/demo", "--port", str(port)],
            cwd=tmp_path,
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
