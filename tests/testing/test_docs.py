"""docs/testing.md runs as written: its client examples against a real server, its test
examples in a pytest of their own, its clock error as printed, and its verb table whole.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
from support import ROOT, typed_verbs

from c2rviz import Client
from c2rviz.protocol.registry import VERBS
from c2rviz.testing.server import TestServer

PAGE = (ROOT / "docs" / "testing.md").read_text()
BLOCKS = re.findall(r"```(\w+)\n(.*?)```", PAGE, re.S)
PYTHON = [code for kind, code in BLOCKS if kind == "python"]
TESTS = [code for code in PYTHON if "def test_" in code]
SCRIPTS = [code for code in PYTHON if "def test_" not in code]
ENV = {**os.environ, "PYTHONPATH": str(ROOT), "PYTHONUNBUFFERED": "1"}


AS_THE_PROGRAM = pytest.mark.c2rviz(clock="real", record=False)
"""The examples' server: what ``c2rviz --no-viewer`` serves (the plugin's, in this process:
the program's wiring on its real clock, without a subprocess's seconds of start-up)."""


@pytest.fixture(scope="module")
def example_runs() -> dict[str, subprocess.CompletedProcess[str]]:
    """Each example's run, by its code: the first example serves two tests with one run."""
    return {}


def run_example(
    code: str, server: TestServer, folder: Path, runs: dict[str, subprocess.CompletedProcess[str]]
) -> subprocess.CompletedProcess[str]:
    """The example run against a fresh server of its own (``server``, unless an earlier test
    of this module ran it against its own already)."""
    if code not in runs:
        script = folder / "example.py"
        script.write_text(code.replace("port=31000", f"port={server.port}"))
        runs[code] = subprocess.run(
            [sys.executable, str(script)], capture_output=True, text=True, timeout=120, env=ENV
        )
    return runs[code]


@AS_THE_PROGRAM
@pytest.mark.parametrize("code", SCRIPTS, ids=[f"example-{i}" for i in range(len(SCRIPTS))])
def test_each_client_example_runs_against_a_server(code, c2rviz_server, tmp_path, example_runs):
    done = run_example(code, c2rviz_server, tmp_path, example_runs)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip()  # it printed what it says it prints


@AS_THE_PROGRAM
def test_the_first_example_prints_what_its_comments_say(c2rviz_server, tmp_path, example_runs):
    done = run_example(SCRIPTS[0], c2rviz_server, tmp_path, example_runs)
    where, collisions = done.stdout.splitlines()
    assert where == "(0.5, 0.2, 0.0, -0.4, 0.0, 0.3, 0.0)"
    assert collisions == "[]"


@pytest.mark.timeout(600)
def test_the_test_examples_pass_in_a_users_pytest(tmp_path):
    assert len(TESTS) >= 2
    (tmp_path / "test_docs_examples.py").write_text("\n\n".join(TESTS))
    (tmp_path / "pytest.ini").write_text("[pytest]\nfilterwarnings = error\n")
    done = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider"]
        + ["-p", "c2rviz.testing.plugin", "-o", "timeout=120"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=600,
        env=ENV,
    )
    out = done.stdout + done.stderr
    assert done.returncode == 0, out
    tests = sum(code.count("def test_") for code in TESTS)
    assert re.search(rf"\b{tests + 1} passed\b", out), out  # (one is run twice: parametrized)


def test_a_bad_clock_is_refused_as_the_page_shows():
    command = next(code for kind, code in BLOCKS if kind == "sh" and "--clock" in code)
    said = next(code for kind, code in BLOCKS if kind == "text" and "--clock" in code)
    argv = command.split()
    assert argv[0] == "c2rviz"
    done = subprocess.run(
        [sys.executable, "-m", "c2rviz", *argv[1:]],
        capture_output=True,
        text=True,
        timeout=120,
        cwd=ROOT,
        env=ENV,
    )
    assert done.returncode == 2
    assert done.stderr == said


def test_the_verb_table_lists_every_typed_method_and_names_the_rest():
    """Every method tagged ``@speaks(verb)`` has its row, under its verb; any other verb
    is ``robot.VERB(*words)`` (docs/commands.md lists every verb: test_registry)."""
    intro, rest = PAGE.split("Every typed method and its verb")[1].split("\n\n", 1)
    assert "any other verb of\n`help`'s list is `robot.VERB(*words)`" in intro
    table = rest.split("\n\n")[0]
    rows = [line.split("|")[1:3] for line in table.splitlines()[2:]]
    typed = typed_verbs(Client)
    verbs = {verb for first, _ in rows for verb in re.findall(r"`(\w+)`", first)}
    assert verbs == set(typed) and verbs <= set(VERBS)
    listed = set()
    for first, methods in rows:
        for method in re.findall(r"`(\w+)\(", methods):
            speaks = getattr(getattr(Client, method, None), "__c2rviz_verb__", None)
            assert speaks in re.findall(r"`(\w+)`", first), f"{method} is not a method of its row"
            listed.add(method)
    missing = {name for names in typed.values() for name in names} - listed
    assert not missing, f"docs/testing.md's table lacks {sorted(missing)}"
