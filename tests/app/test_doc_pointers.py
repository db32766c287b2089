"""What the help texts and the ini point to is there, and the pages they point to say true
things (issue 39, rough edge 9).

- Every README section and docs page that ``c2rviz --help``, ``c2rviz-cli --help``,
  ``c2rviz-play --help`` or ``cmdinterpreter.ini`` names exists (they once named README
  sections that had moved to docs/: "Several robots", "Motion", "Limits" ...).
- docs/cells.md's session on the two-arm cell runs as written (``collisions`` reports the
  other robot too), against ``c2rviz --cell twoarms``.
- docs/configuration.md names the doors' port flags, and only flags that exist.
- ``c2rviz-play --help`` says that for a CRCL program ``--port`` is the CRCL port.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from typing import Any

import pytest
from support import ROOT, Client

from c2rviz.app import cli
from c2rviz.clients import player, repl

README = (ROOT / "README.md").read_text()
SECTIONS = {m.strip() for m in re.findall(r"^#+ (.+)$", README, re.MULTILINE)}


def helps() -> dict[str, str]:
    """Each help text (as one line of words) and the ini, by name."""
    texts = {
        "c2rviz --help": cli.build_parser().format_help(),
        "c2rviz-cli --help": repl.build_parser().format_help(),
        "c2rviz-play --help": player.build_parser().format_help(),
        "cmdinterpreter.ini": (ROOT / "cmdinterpreter.ini").read_text().replace("\n#", ""),
    }
    return {name: " ".join(text.split()) for name, text in texts.items()}


def pointers(text: str) -> tuple[list[str], list[str]]:
    """The README sections (``README "A", "B"``, ``README: A``) and docs pages a text names."""
    sections = []
    for m in re.finditer(r'README(?::\s*([A-Z][\w ]*?)(?=[);,.]|$)|\s+((?:"[^"]+",?\s*)+))', text):
        if m.group(1):
            sections.append(m.group(1).strip())
        else:
            sections += re.findall(r'"([^"]+)"', m.group(2))
    return sections, re.findall(r"docs/[\w-]+\.md", text)


@pytest.mark.parametrize("name", list(helps()))
def test_what_a_help_text_or_the_ini_points_to_exists(name: str) -> None:
    sections, pages = pointers(helps()[name])
    assert [s for s in sections if s not in SECTIONS] == [], (
        f"{name} names them; README has {SECTIONS}"
    )
    assert [p for p in pages if not (ROOT / p).is_file()] == []


def test_the_pointer_reader_finds_both_forms() -> None:
    text = 'many (README: Several robots) and (README "Motion", "Cartesian commands") docs/x.md'
    assert pointers(text) == (["Several robots", "Motion", "Cartesian commands"], ["docs/x.md"])


def session(page: str) -> list[tuple[str, str]]:
    """The page's one ``> command`` / reply session: (command, reply) pairs."""
    lines = (ROOT / "docs" / page).read_text().splitlines()
    steps = [(line[2:], lines[k + 1]) for k, line in enumerate(lines) if line.startswith("> ")]
    assert steps, page
    return steps


def test_the_cells_page_session_runs_as_written(c2rviz_process: Callable[..., Any]) -> None:
    proc = c2rviz_process("--cell", "twoarms", "--no-viewer")  # the first port: left's
    client = Client("127.0.0.1", proc.port)
    try:
        for command, reply in session("cells.md"):
            assert (command, client.ask(command)) == (command, reply)
    finally:
        client.close()


def test_the_configuration_page_names_the_doors_flags_and_only_real_ones() -> None:
    page = (ROOT / "docs" / "configuration.md").read_text()
    named = set(re.findall(r"`(--[a-z][a-z-]*)", page))
    flags = {o for a in cli.build_parser()._actions for o in a.option_strings}
    assert named - flags == set()
    for door in ("--port", "--crcl-port", "--no-crcl", "--rosbridge-port", "--no-rosbridge"):
        assert door in named, door


def test_the_players_port_is_the_crcl_port_for_a_crcl_program() -> None:
    text = helps()["c2rviz-play --help"]
    assert "for a CRCL program (FILE.xml), the CRCL port (default 64444)" in text


def test_the_modules_pyproject_names_exist() -> None:
    """Its comments once cited ``viewer.py`` (gone) and trimesh for the marker shapes."""
    text = (ROOT / "pyproject.toml").read_text()
    comments = " ".join(line.split("#", 1)[1] for line in text.splitlines() if "#" in line)
    named = re.findall(r"[\w/]+\.py\b", comments)
    assert named, comments
    files = {p.relative_to(ROOT / "c2rviz").as_posix() for p in (ROOT / "c2rviz").rglob("*.py")}
    missing = [
        n
        for n in named
        if not (ROOT / n).is_file() and not any(f == n or f.endswith("/" + n) for f in files)
    ]
    assert missing == [], missing
    assert "marker" not in re.search(r'"trimesh[^\n]*', text).group(0)  # numpy makes them
