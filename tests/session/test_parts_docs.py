"""docs/parts.md runs as written: each session against the bundled fanuc on virtual time,
and its limits table names the code's values."""

from __future__ import annotations

import math
import re

import pytest
from support import ROOT, Client, ServerLimits, ServerThread, load_robot

from c2rviz.protocol.verbs import parts as verbs_parts
from c2rviz.world import part_rules, part_world, parts
from c2rviz.world.virtual_clock import VirtualClock

DOC = ROOT / "docs" / "parts.md"
NUMBER = re.compile(r"-?\d+(?:\.\d+)?(?:e[-+]?\d+)?")


def sessions() -> list[list[tuple[str, str]]]:
    """The ``> command`` / reply pairs of each code block."""
    blocks, block, inside = [], [], False
    lines = DOC.read_text().splitlines()
    for number, line in enumerate(lines):
        if line.lstrip().startswith("```"):
            if block:
                blocks.append(block)
            block, inside = [], not inside
        elif inside and line.startswith("> "):
            block.append((line[2:].strip(), lines[number + 1].strip()))
    return blocks


def same(got: str, want: str) -> bool:
    if NUMBER.sub("#", got) != NUMBER.sub("#", want):
        return False
    pairs = zip(map(float, NUMBER.findall(got)), map(float, NUMBER.findall(want)))
    return all(abs(a - b) <= 1e-3 * max(1.0, abs(b)) for a, b in pairs)


@pytest.mark.parametrize("steps", sessions(), ids=lambda s: s[1][0].split()[0])
def test_a_session_of_the_page_replies_as_shown(steps: list[tuple[str, str]]) -> None:
    server = ServerThread(load_robot("fanuc_lrmate200id"), ServerLimits(), clock=VirtualClock())
    server.start()
    client = Client(server.host, server.port)
    try:
        for line, reply in steps:
            got = client.ask(line)
            assert same(got, reply), f"{line!r}: {got!r}, the page says {reply!r}"
    finally:
        client.close()
        server.stop()


def test_the_page_holds_its_sessions() -> None:
    assert len(sessions()) == 3


def test_the_limits_table_is_the_code() -> None:
    table = DOC.read_text().split("## Limits")[1]
    values = {
        "MAX_PARTS": f"| {parts.MAX_PARTS} |",
        "PART_SIZE_M": f"| {parts.PART_SIZE_M[0]:g}..{parts.PART_SIZE_M[1]:g} m |",
        "MAX_GOALS": f"| {part_rules.MAX_GOALS} |",
        "GRIP_TOL_M": f"| {part_rules.GRIP_TOL_M * 1000:g} mm |",
        "CUP_M": f"| {part_rules.CUP_M * 1000:g} mm |",
        "REST_TOL_M": f"| {part_world.REST_TOL_M * 1000:g} mm |",
        "OVERLAP_TOL_M": f"| {part_world.OVERLAP_TOL_M * 1000:g} mm |",
        "CHECK_MARGIN_M": f"| {parts.CHECK_MARGIN_M * 1000:g} mm |",
    }
    for name, cell in values.items():
        row = next(line for line in table.splitlines() if f".{name}`" in line)
        assert cell in row, (name, row)
    assert verbs_parts.PART_SIZE_M == parts.PART_SIZE_M  # the parser's copy
    assert part_rules.DEFAULT_TOL_M == 0.005 and math.degrees(part_rules.DEFAULT_TOL_RAD) == 5.0
