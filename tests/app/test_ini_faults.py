"""The ini's ``[faults]``: started or scheduled when the server starts; a bad entry stops
the start with the entry named."""

from __future__ import annotations

from pathlib import Path

import pytest
from support import ROOT

from c2rviz.errors import ConfigError
from c2rviz.testing.server import TestServer


def ini(tmp_path: Path, faults: str) -> Path:
    path = tmp_path / "cmdinterpreter.ini"
    own = (ROOT / "cmdinterpreter.ini").read_text()
    path.write_text(own.replace("urdf = robots/", f"urdf = {ROOT}/robots/") + faults)
    return path


def test_the_ini_starts_and_schedules_faults(tmp_path: Path):
    text = "\n[faults]\nearly = after 5 estop\nshaky = noise 0.002\nlegs = stall joint_u\n"
    server = TestServer({"ini": ini(tmp_path, text), "clock": "virtual", "record": False})
    server.start()
    try:
        # (virtual time with no client connected runs on to the estop at once)
        assert server.run("faults") == (
            "ok noise 0.002 since 0.000; stall joint_u since 0.000; estop since 5.000"
        )
        assert server.run("move 0 1") == (
            "error: emergency stop since t=5.000 (fault clear estop, then reset)"
        )
    finally:
        server.stop()


@pytest.mark.parametrize(
    ("entry", "why"),
    [
        ("x = bogus", "[faults] x = 'bogus': fault: unknown fault 'bogus'"),
        ("x = stall joint_q", "no joint 'joint_q'"),
        ("x = after -1 estop", "S '-1' is not a time"),
        ("x = clear all", "clear is not a fault to start"),
    ],
)
def test_a_bad_ini_fault_names_its_entry(tmp_path: Path, entry: str, why: str):
    with pytest.raises(ConfigError) as raised:
        TestServer({"ini": ini(tmp_path, f"\n[faults]\n{entry}\n"), "record": False})
    assert why in str(raised.value)
