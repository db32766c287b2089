"""docs/planning.md runs as written: its transcript replayed against the real program, and
its settings (and docs/limits.md's planning bounds) the ones the code uses."""

from __future__ import annotations

import dataclasses
import math
import re

from support import ROOT, Client

from c2rviz.app import cli, config
from c2rviz.planning import MAX_TIMEOUT_S, SEEDS
from c2rviz.session import SessionDefaults
from c2rviz.session.guarded import DRAWS, TRIES
from c2rviz.session.worker import MAX_QUEUE

DOC = ROOT / "docs" / "planning.md"


def transcript() -> list[tuple[str, str]]:
    """The example's (line, reply) pairs."""
    text = DOC.read_text().split("## A workcell example")[1]
    block = text.split("```")[1].strip().splitlines()
    return [(block[k][2:], block[k + 1]) for k in range(0, len(block), 2)]


def test_the_workcell_example_replies_as_written(c2rviz_process) -> None:
    assert "c2rviz --seed 1" in DOC.read_text()
    # Virtual time: the same replies (docs/testing.md), without waiting out its moves.
    proc = c2rviz_process("--no-viewer", "--seed", "1", "--clock", "virtual")
    client = Client("127.0.0.1", proc.port)
    try:
        pairs = transcript()
        assert len(pairs) > 10 and any(line.startswith("plan joints") for line, _ in pairs)
        for line, reply in pairs:
            assert client.ask(line) == reply, line
    finally:
        client.close()


def test_the_settings_table_is_the_code() -> None:
    text = DOC.read_text()
    table = text.split("| Setting | Default |")[1].split("\n\n")[0]
    rows = [
        [c.strip() for c in re.split(r"(?<!\\)\|", row.strip("|"))]  # "\|" is in a cell
        for row in table.splitlines()[2:]
    ]
    flags = {a.option_strings[0]: a.dest for a in cli.build_parser()._actions if a.option_strings}
    defaults = SessionDefaults()
    seen = set()
    for _what, default, flag, key, _verb, allowed in rows:
        key = key.strip("`")
        if key == "guard":
            assert allowed == ", ".join(config._CHOICES["guard"]) and not defaults.guard
            continue
        field, kind, low, high = config._OPTIONS[key]
        assert flags[flag.strip("`")] == field
        assert [float(v) for v in allowed.split("..")] == [low, high]
        if field in config._TO_SI:
            name, to_si = config._TO_SI[field]
            assert math.isclose(to_si(kind(default)), getattr(defaults, name))
        else:
            assert default == "a fresh one" or kind(default) == getattr(defaults, field)
        seen.add(field)
    assert seen == {"plan_timeout_s", "plan_step_deg", "plan_tool_step_mm", "plan_seed"}
    assert config._OPTIONS["plan_timeout"][3] == MAX_TIMEOUT_S
    assert config._OPTIONS["seed"][3] == SEEDS - 1
    assert {f.name for f in dataclasses.fields(SessionDefaults)} >= {"plan_around", "plan_seed"}


def test_the_fixed_bounds_are_in_docs_limits() -> None:
    text = (ROOT / "docs" / "limits.md").read_text()
    section = text.split("## Planning and the guard")[1]
    assert f"| {MAX_QUEUE} | `session.worker.MAX_QUEUE` |" in section
    assert f"| {TRIES} | `session.guarded.TRIES` |" in section
    assert f"| {DRAWS} | `session.guarded.DRAWS` |" in section
    assert re.search(r"\| 0\.5 ms \| `session\.worker\.SWITCH_S` \|", section)
