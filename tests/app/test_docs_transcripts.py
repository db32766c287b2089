"""Every session written in the docs (``> command`` lines, each followed by its reply)
runs as written against a real server, one fresh server per block, and replies as shown.

Numbers are compared within 1e-3 (relative, or absolute near zero); a reply that depends
on a random draw (``rand``) or on the wall clock (``status`` of a travelling
arm) is compared by its kind, ``ok`` or ``error``, and its words.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import pytest
from support import ROOT

NUMBER = re.compile(r"-?\d+(?:\.\d+)?(?:e[-+]?\d+)?")
WORDS_ONLY = re.compile(r"^(rand|status)\b")
"""Commands whose numbers vary from run to run."""
OWN_TEST = {"planning.md", "faults.md", "cells.md", "parts.md"}
"""Pages whose sessions a test of their own replays reply for reply (planning's, with
``--seed 1``: tests/planning/test_planning_docs.py; the cell's, on ``--cell twoarms``:
tests/app/test_doc_pointers.py; faults.md's: tests/app/test_faults_docs.py; parts.md's:
tests/session/test_parts_docs.py)."""


@dataclass(frozen=True)
class Step:
    command: str
    reply: str


def transcripts(page: Path) -> list[list[Step]]:
    """The ``> command`` / reply sessions of a Markdown page's code blocks."""
    blocks, block, inside = [], [], False
    lines = page.read_text().splitlines()
    for number, line in enumerate(lines):
        if line.startswith("```"):
            if block:
                blocks.append(block)
            block, inside = [], not inside
        elif inside and line.startswith("> "):
            command = re.split(r"\s{2,}#", line[2:])[0].strip()
            reply = re.split(r"\s{2,}", lines[number + 1])[0].strip()
            block.append(Step(command, reply))
    return blocks


PAGES = [p for p in sorted((ROOT / "docs").glob("*.md")) if p.name not in OWN_TEST]
CASES = [
    pytest.param(steps, id=f"{page.name}-{k}")
    for page in PAGES
    for k, steps in enumerate(transcripts(page))
]


def same(command: str, got: str, want: str) -> bool:
    """``got`` reads as ``want``: the same words, and numbers within 1e-3."""
    if NUMBER.sub("#", got) != NUMBER.sub("#", want):
        return bool(WORDS_ONLY.match(command)) and got.split()[:1] == want.split()[:1]
    if WORDS_ONLY.match(command):
        return True
    pairs = zip(map(float, NUMBER.findall(got)), map(float, NUMBER.findall(want)))
    return all(abs(a - b) <= 1e-3 * max(1.0, abs(b)) for a, b in pairs)


def test_the_docs_hold_sessions() -> None:
    assert len(CASES) >= 4, [c.id for c in CASES]


@pytest.mark.parametrize("steps", CASES)
def test_a_documented_session_replies_as_shown(steps: list[Step], server, connect) -> None:
    client = connect(server)
    for step in steps:
        got = client.ask(step.command)
        said = f"{step.command!r}: {got!r}, the docs say {step.reply!r}"
        assert same(step.command, got, step.reply), said
