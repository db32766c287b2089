"""The part faults meet a CRCL client as they meet the text port: they act on the world.
A SetEndEffector grasp slips under ``fault slip 1`` (done, the fingers shut on nothing),
and ``fault drop`` lets go of what a CRCL grasp took."""

from __future__ import annotations

import pytest
from crcl_support import DONE, actuate, command

PICK = {1: 0.0, 2: 0.3, 3: -0.3, 4: 0.0, 5: -0.9707963, 6: 0.0}  # the fanuc pointing down
LIFT = {2: 0.0, 3: 0.0, 5: -1.5707963}


@pytest.mark.wall_clock
def test_a_crcl_grasp_slips_and_a_crcl_held_part_drops(start_crcl, crcl_connect, connect):
    server = start_crcl("fanuc_lrmate200id")
    text = connect(server)
    assert text.ask("object table box 0.4,0.6,0.05 0.45,0,0.154,0,0,0") == "ok"
    assert text.ask("part p1 box 0.03,0.03,0.17 0.4438,0,0.264,0,0,0") == "ok"
    assert text.ask("fault slip 1") == "ok"
    client = crcl_connect(server)
    steps = [
        command("InitCanon", 1),
        command("SetEndEffector", 2, "<Setting>1</Setting>"),
        actuate(3, PICK),
        command("SetEndEffector", 4, "<Setting>0</Setting>"),
    ]
    for number, doc in enumerate(steps, start=1):
        got = client.run(doc, number).command_status
        assert got.state == DONE, (number, got.description)
    assert server.opening() == 0.0  # shut on nothing, as on a miss
    assert text.ask("part p1").endswith(" resting on table")
    assert text.ask("fault clear slip") == "ok"
    steps = [
        command("SetEndEffector", 5, "<Setting>1</Setting>"),
        command("SetEndEffector", 6, "<Setting>0</Setting>"),
        actuate(7, LIFT),
    ]
    for number, doc in enumerate(steps, start=5):
        got = client.run(doc, number).command_status
        assert got.state == DONE, (number, got.description)
    assert abs(server.opening() - 0.5) < 1e-6  # this time it took the part
    assert text.ask("part p1").endswith(" held")
    assert text.ask("fault drop") == "ok"
    assert text.ask("sleep 1") == "ok"
    assert text.ask("part p1").endswith(" resting on table")
