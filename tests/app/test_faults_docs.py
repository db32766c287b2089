"""docs/faults.md's sessions, replayed reply for reply on a fresh virtual-time server
each (the page's times are the world's clock, so only virtual time repeats them)."""

from __future__ import annotations

import pytest
from support import ROOT, Client
from test_docs_transcripts import Step, same, transcripts

from c2rviz.testing.server import TestServer

PARTS_ROBOT = "fanuc_lrmate200id"
"""The robot of a session with parts (docs/parts.md's: its parallel gripper)."""
BLOCKS = transcripts(ROOT / "docs" / "faults.md")


def test_the_page_holds_sessions():
    assert len(BLOCKS) >= 3


@pytest.mark.parametrize("steps", BLOCKS, ids=[f"faults.md-{k}" for k in range(len(BLOCKS))])
def test_a_documented_fault_session_replies_as_shown(steps: list[Step]):
    options: dict[str, object] = {"clock": "virtual", "record": False}
    if any(step.command.startswith("part ") for step in steps):
        options["robot"] = PARTS_ROBOT  # the part faults' sessions: a robot with a gripper
    server = TestServer(options).start()
    try:
        client = Client(server.host, server.port)
        try:
            for step in steps:
                got = client.ask(step.command)
                said = f"{step.command!r}: {got!r}, the docs say {step.reply!r}"
                assert got == step.reply or same(step.command, got, step.reply), said
        finally:
            client.close()
    finally:
        server.stop()


def test_the_pages_limits_are_the_codes():
    from c2rviz.protocol.verbs.faults import FAULT_KINDS, FAULT_TIME_S, LATENCY_MS, NOISE_SIGMA
    from c2rviz.world.faults import MAX_SCHEDULED

    faults = (ROOT / "docs" / "faults.md").read_text()
    limits = (ROOT / "docs" / "limits.md").read_text()
    assert f"| 0..{FAULT_TIME_S:g} s |" in faults
    assert f"at most {NOISE_SIGMA:g} (the connection's unit)" in faults
    assert f"| 0..{LATENCY_MS:g} ms each |" in faults
    assert f"| faults scheduled at once per robot | {MAX_SCHEDULED} |" in faults
    assert f"| 0..{FAULT_TIME_S:g}; {MAX_SCHEDULED} |" in limits
    assert f"| (0, {NOISE_SIGMA:g}]; 0..{LATENCY_MS:g} |" in limits
    for kind in FAULT_KINDS:
        assert f"| `{kind}" in faults, kind
