"""A CRCL client picks and places a part: SetEndEffector grasps and releases by the same
rule as the text port's ``grip`` (docs/parts.md)."""

from __future__ import annotations

from crcl_support import DONE, actuate, command

PICK = {1: 0.0, 2: 0.3, 3: -0.3, 4: 0.0, 5: -0.9707963, 6: 0.0}  # the fanuc pointing down
LIFT = {2: 0.0, 3: 0.0, 5: -1.5707963}
AWAY = {1: 1.5707963}  # the jaws above the floor beside the table


def test_a_crcl_client_picks_a_part_off_the_table_and_drops_it_beside(
    start_crcl, crcl_connect, connect
) -> None:
    server = start_crcl("fanuc_lrmate200id")
    text = connect(server)
    assert text.ask("object table box 0.4,0.6,0.05 0.45,0,0.154,0,0,0") == "ok"
    assert text.ask("part p1 box 0.03,0.03,0.17 0.4438,0,0.264,0,0,0") == "ok"
    assert text.ask("watch 1") == "ok"
    client = crcl_connect(server)
    steps = [
        command("InitCanon", 1),
        command("SetEndEffector", 2, "<Setting>1</Setting>"),
        actuate(3, PICK),
        command("SetEndEffector", 4, "<Setting>0</Setting>"),
        actuate(5, LIFT),
        actuate(6, AWAY),
        command("SetEndEffector", 7, "<Setting>1</Setting>"),
    ]
    for number, doc in enumerate(steps, start=1):
        got = client.run(doc, number).command_status
        assert got.state == DONE, (number, got.description)
        if number == 4:
            assert abs(server.opening() - 0.5) < 1e-6  # the fingers stopped on the 30 mm part
    events = []
    while not events or not events[-1].startswith("event resting"):
        line = text.read_line()
        if line.startswith(("event grasped", "event released", "event resting")):
            events.append(line)
    assert events == ["event grasped p1", "event released p1", "event resting p1 on floor"]
    assert text.ask("part p1").endswith(" resting on floor")
