"""Parts through the real server, on virtual time: the verbs, the grasp rule and its
misses, release (resting and falling), stacking, the guard with a carried part, goals
and the score, the watch events, and bad input that changes nothing.

The scene: the bundled fanuc (its parallel gripper, 60 mm open) pointing down at
``PICK``; its jaws' centre is then at ``JAWS``. A table's top lies below the fingertips;
a tall part stands on it with its top just under the hand, the jaws around it.
"""

from __future__ import annotations

import math

import pytest
from support import Client, ServerLimits, ServerThread, load_robot
from watch_support import ask

from c2rviz.world.virtual_clock import VirtualClock

PICK = "0,0.3,-0.3,0,-0.9707963,0"  # pointing straight down
LIFT = "0,0,0,0,-1.5707963,0"  # straight down, 210 mm higher
OFF_TABLE = "1.5707963,0,0,0,-1.5707963,0"  # the jaws above the floor beside the table
DOWN = "0,0.32,-0.33,0,-0.9207963,0"  # from PICK, the jaws 17 mm lower
JAWS = (0.4438, 0.0, 0.339)
TABLE_TOP = 0.179
TABLE = f"object table box 0.4,0.6,0.05 0.45,0,{TABLE_TOP - 0.025:.4f},0,0,0"
TALL = 0.17  # the part's height: its top 10 mm above the jaws' centre


def _part(name: str = "p1", width: float = 0.03, dy: float = 0.0, extra: str = "") -> str:
    x, y, _ = JAWS
    z = TABLE_TOP + TALL / 2
    return f"part {name} box {width},{width},{TALL} {x},{y + dy},{z:.4f},0,0,0 {extra}".strip()


@pytest.fixture
def fanuc():
    server = ServerThread(load_robot("fanuc_lrmate200id"), ServerLimits(), clock=VirtualClock())
    server.start()
    client = Client(server.host, server.port)
    try:
        yield server, client
    finally:
        client.close()
        server.stop()


def _at_pick(client: Client) -> None:
    for line in ("grip 1", TABLE, f"joints {PICK}"):
        assert client.ask(line) == "ok", line


def _pose(reply: str) -> list[float]:
    return [float(v) for v in reply.split()[1].split(",")]


def test_closing_on_a_part_between_the_fingers_grasps_it_and_it_moves_with_the_link(fanuc):
    server, client = fanuc
    _at_pick(client)
    assert client.ask(_part()) == "ok"
    assert client.ask("part p1").endswith(" resting on table")
    reply = client.ask("grip 0")
    assert reply.startswith("ok 0.5"), reply  # where the fingers touch 30 mm: half open
    assert float(reply.split()[1]) == pytest.approx(0.5, abs=0.01)
    assert client.ask("grip") == reply
    assert client.ask("part p1").endswith(" held")
    before = _pose(client.ask("part p1"))
    assert client.ask(f"joints {LIFT}") == "ok"
    after = _pose(client.ask("part p1"))
    assert after[2] - before[2] > 0.15  # lifted with the hand
    assert client.ask("collisions") == "ok none"  # the fingers may touch what they hold


@pytest.mark.parametrize(
    ("setup", "part_line"),
    [
        ((), _part(width=0.07)),  # too wide for the open fingers
        ((), _part(dy=0.06)),  # beside the fingers, not between them
        (("grip 0",), _part()),  # the fingers closed already
    ],
    ids=["too-wide", "not-between", "already-closed"],
)
def test_the_misses_grasp_nothing(fanuc, setup, part_line):
    server, client = fanuc
    _at_pick(client)
    for line in setup:
        assert client.ask(line) == "ok"
    assert client.ask(part_line) == "ok"
    assert client.ask("grip 0") == "ok"  # no opening reported: nothing taken
    assert client.ask("grip") == "ok 0"
    assert client.ask("part p1").endswith(" resting on table")


def test_closing_not_far_enough_to_touch_grasps_nothing(fanuc):
    _, client = fanuc
    _at_pick(client)
    assert client.ask(_part()) == "ok"
    assert client.ask("grip 0.9") == "ok"  # 54 mm apart: the 30 mm part stays loose
    assert client.ask("part p1").endswith(" resting on table")


def test_a_part_released_on_the_table_rests_and_one_released_above_falls(fanuc):
    server, client = fanuc
    _at_pick(client)
    assert client.ask(_part()) == "ok"
    assert client.ask("grip 0").startswith("ok 0.")
    assert client.ask("grip 1") == "ok"  # put back where it was: resting at once
    assert client.ask("part p1").endswith(" resting on table")
    assert client.ask("grip 0").startswith("ok 0.")
    assert client.ask(f"joints {LIFT}") == "ok"
    t0 = server.call(server.world.clock.now)
    high = _pose(client.ask("part p1"))[2]
    assert client.ask("grip 1") == "ok"
    assert client.ask("part p1").endswith(" free")  # falling, on the world's clock
    assert client.ask("sleep 1") == "ok"  # virtual: at once
    reply = client.ask("part p1")
    assert reply.endswith(" resting on table"), reply
    low = _pose(reply)[2]
    assert low == pytest.approx(TABLE_TOP + TALL / 2, abs=1e-3)
    times = [t for t in server.call(lambda: list(server.scene.part_times)) if t >= t0]
    assert times[-1] - times[0] == pytest.approx(math.sqrt(2 * (high - low) / 9.81), abs=0.02)


def test_a_part_released_beside_the_table_falls_to_the_floor(fanuc):
    _, client = fanuc
    _at_pick(client)
    assert client.ask(_part()) == "ok"
    assert client.ask("grip 0").startswith("ok 0.")
    assert client.ask(f"joints {LIFT}") == "ok"
    assert client.ask(f"joints {OFF_TABLE}") == "ok"
    assert client.ask("grip 1") == "ok"
    assert client.ask("sleep 2") == "ok"
    reply = client.ask("part p1")
    assert reply.endswith(" resting on floor"), reply
    assert _pose(reply)[2] == pytest.approx(TALL / 2, abs=1e-4)


def test_parts_stack_and_a_part_whose_support_is_taken_falls(fanuc):
    _, client = fanuc
    assert client.ask("part a box 0.1,0.1,0.1 0,0.6,0.05,0,0,0") == "ok"
    assert client.ask("part a").endswith(" resting on floor")
    assert client.ask("part b box 0.05,0.05,0.05 0,0.6,0.3,0,0,0 type=cube") == "ok"
    assert client.ask("part b").endswith(" free")  # put in the air: it stays there
    assert client.ask("part c box 0.05,0.05,0.05 0,0.6,0.125,0,0,0") == "ok"
    assert client.ask("part c").endswith(" resting on a")
    assert client.ask("part a remove") == "ok"
    assert client.ask("sleep 1") == "ok"
    assert client.ask("part c").endswith(" resting on floor")
    reply = client.ask("parts")
    assert reply.startswith("ok b:0,0.6,0.3,0,0,0:free;c:0,0.6,0.025,0,0,0:resting on floor")


def test_the_guard_refuses_a_move_sweeping_a_carried_part_through_the_table(fanuc):
    _, client = fanuc
    _at_pick(client)
    assert client.ask(_part()) == "ok"
    assert client.ask("guard on") == "ok"
    assert client.ask("collisions") == "ok none"
    reply = client.ask(f"joints {DOWN}")  # a free part is an obstacle (but to the fingers)
    assert reply == "error: gripper_hand would hit p1 at the target"
    assert client.ask("grip 0").startswith("ok 0.")
    reply = client.ask(f"joints {DOWN}")
    assert reply == "error: p1 would hit table at the target"
    assert client.ask(f"joints {LIFT}") == "ok"  # up and away is free


def test_goals_and_the_score(fanuc):
    _, client = fanuc
    assert client.ask("degrees") == "ok"
    assert client.ask("part p1 box 0.05,0.05,0.05 0.5,0.5,0.025,0,0,0 type=cube") == "ok"
    assert client.ask("part p2 box 0.05,0.05,0.05 0.5,-0.5,0.025,0,0,10") == "ok"
    assert client.ask("score") == "ok no goals"
    assert client.ask("goal p1 0.5,0.5,0.025,0,0,0") == "ok"
    assert client.ask("goal p2 0.5,-0.5,0.025,0,0,0 0.001,1") == "ok"
    assert client.ask("goal type=gear 0,0,0,0,0,0") == "ok"  # none of that type: missing
    assert client.ask("score") == "ok 1/3 met; p2 0.0 mm 10.0 deg off; type=gear missing"
    assert client.ask("goal p3 0,0,0,0,0,0").startswith("error: no part named 'p3'")
    assert client.ask("goal type=gear remove") == "ok"
    assert client.ask("goal p2 0.5,-0.5,0.025,0,0,10") == "ok"
    assert client.ask("score") == "ok 2/2 met"
    assert client.ask("goal all remove") == "ok"
    assert client.ask("score") == "ok no goals"


@pytest.mark.parametrize(
    ("line", "error"),
    [
        ("part t box 0.1,0.1,0.1 0.45,0,0.2,0,0,0", "mm inside 'table': place it on top or beside"),
        ("part table box 0.1,0.1,0.1 2,0,0.05,0,0,0", "'table' is already an object's"),
        ("part link_6 box 0.1,0.1,0.1 2,0,0.05,0,0,0", "already an object's or a link's"),
        ("part q box 1e308,1,1 2,0,0,0,0,0", "part size 1e+308 m is outside 0.001..2 m"),
        ("part q box 3,1,1 2,0,0,0,0,0", "part size 3 m is outside"),
        ("part nope", "no part named 'nope' (parts: p1)"),
        ("part nope remove", "no part named 'nope'"),
        ("part p1 box 0.1,0.1,0.1 -2,0,0.05,0,0,0", "'p1' is already a part"),
    ],
    ids=["inside", "object-name", "link-name", "huge", "too-big", "ask", "remove", "dup"],
)
def test_bad_input_is_refused_and_changes_nothing(fanuc, line, error):
    _, client = fanuc
    assert client.ask(TABLE) == "ok"
    assert client.ask("part p1 box 0.05,0.05,0.05 2,2,0.025,0,0,0") == "ok"
    before = client.ask("parts")
    reply = client.ask(line)
    assert reply.startswith("error: ") and error in reply, reply
    assert client.ask("parts") == before


def test_too_many_parts_are_refused(fanuc):
    server, client = fanuc
    server.call(lambda: setattr(server.world.parts.parts, "max_parts", 2))
    assert client.ask("part a sphere 0.01 0,1,0.01") == "ok"
    assert client.ask("part b sphere 0.01 0,1.1,0.01") == "ok"
    reply = client.ask("part c sphere 0.01 0,1.2,0.01")
    assert reply == "error: the world already holds 2 parts, its limit; remove one first"
    assert client.ask("part all remove") == "ok"
    assert client.ask("parts") == "ok none"


def test_watch_tells_grasped_released_and_resting(fanuc):
    server, client = fanuc
    watcher = Client(server.host, server.port)
    try:
        assert watcher.ask("watch 1") == "ok"
        _at_pick(client)
        assert client.ask(_part()) == "ok"
        assert client.ask("grip 0").startswith("ok 0.")
        assert client.ask(f"joints {LIFT}") == "ok"
        assert client.ask("grip 1") == "ok"
        assert client.ask("sleep 1") == "ok"
        seen: list[str] = []
        assert ask(watcher, "watch 1", seen) == "ok"
        events = [line for line in seen if line.startswith("event ") and "collision" not in line]
        assert events == ["event grasped p1", "event released p1", "event resting p1 on table"]
    finally:
        watcher.close()


def test_a_plan_goes_around_a_post_the_carried_part_would_hit(fanuc):
    _, client = fanuc
    _at_pick(client)
    assert client.ask(_part()) == "ok"
    assert client.ask("grip 0").startswith("ok 0.")
    assert client.ask(f"joints {LIFT}") == "ok"
    # lower than the fingertips, higher than the bottom of the part they hold
    assert client.ask("object post box 0.05,0.05,0.45 0.272,0.272,0.225,0,0,0") == "ok"
    for line in ("collisions", "guard on", "motion on"):
        assert client.ask(line) == ("ok none" if line == "collisions" else "ok")
    reply = client.ask(f"joints {OFF_TABLE}")
    assert reply.startswith("error: p1 would hit post at "), reply
    reply = client.ask(f"plan joints {OFF_TABLE}")
    assert reply.startswith("ok ") and "waypoints" in reply, reply
    assert client.ask("part p1").endswith(" held")
    assert _pose(client.ask("part p1"))[1] > 0.3  # carried round the post


def test_a_part_on_an_object_that_is_removed_falls(fanuc):
    _, client = fanuc
    assert client.ask(TABLE) == "ok"
    assert client.ask(_part()) == "ok"
    assert client.ask("part p1").endswith(" resting on table")
    assert client.ask("object table remove") == "ok"
    assert client.ask("sleep 1") == "ok"
    reply = client.ask("part p1")
    assert reply.endswith(" resting on floor") and _pose(reply)[2] == pytest.approx(TALL / 2)


def test_with_motion_on_the_fingers_travel_onto_the_part_and_reply_where_they_stop(fanuc):
    server, client = fanuc
    _at_pick(client)
    assert client.ask(_part()) == "ok"
    assert client.ask("motion on") == "ok"
    t0 = server.call(server.world.clock.now)
    assert client.ask("grip 0") == "ok 0.5"  # on arrival, half a stroke later
    assert server.call(server.world.clock.now) - t0 == pytest.approx(0.15, abs=0.02)
    assert client.ask("part p1").endswith(" held")
