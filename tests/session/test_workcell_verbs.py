"""Collisions and the workcell through the real server: objects, collisions, guarded commands."""

from __future__ import annotations

import re

import pytest
from support import ROBOTS, ServerThread, load_robot

from c2rviz.session import ServerLimits
from c2rviz.world.virtual_clock import parse_clock

FOLDED = {
    "motoman_sia20d": ("0,-106,0,122,0,0,0", "base_link~link_b,base_link~link_r,base_link~link_u"),
    "fanuc_lrmate200id": ("0,0,0,0,124,0", "link_4~link_6"),
    "kuka_lwr": ("0,0,0,0,0,90,0", "lwr_5_link~lwr_7_link"),
}
# A box to the motoman's left (+y), where joint_s swung by 90 degrees carries its
# wrist with the arm held out at joint_l 60 degrees.
BOX = "object table box 0.2,0.2,0.2 0,0.8,0.85,0,0,0"
REACH = "0,60,0,0,0,0,0"  # the arm held out along +x
INTO = "90,60,0,0,0,0,0"  # ... swung round to +y: through the box
BEYOND = "-90,60,0,0,0,0,0"  # ... swung the other way: free
THROUGH = "180,60,0,0,0,0,0"


@pytest.mark.parametrize("name", list(ROBOTS))
def test_home_is_free_and_a_folded_arm_names_its_pairs(start_server, connect, name: str):
    client = connect(start_server(name))
    client.ask("degrees")
    assert client.ask("collisions") == "ok none"
    q, pairs = FOLDED[name]
    assert client.ask(f"j {q}") == "ok"
    reply = client.ask("collisions")
    assert reply.startswith("ok ") and set(FOLDED[name][1].split(",")) <= set(reply[3:].split(","))


def test_objects_are_added_listed_replaced_and_removed(server: ServerThread, connect):
    client = connect(server)
    assert client.ask("objects") == "ok none"
    assert client.ask(BOX) == "ok"
    assert client.ask("object ball sphere 0.1 0.5,0,0.2") == "ok"
    assert client.ask("object pipe cylinder 0.05,0.5 0.5,0.5,0,0,0,0") == "ok"
    assert client.ask("objects") == "ok table,ball,pipe"
    assert client.ask("object ball sphere 0.2 0.5,0,0.2") == "ok"  # replaced, same place
    assert client.ask("objects") == "ok table,ball,pipe"
    assert client.ask("object ball remove") == "ok"
    assert client.ask("objects") == "ok table,pipe"
    assert client.ask("object ghost remove").startswith("error: ")
    assert client.ask("object all remove") == "ok"
    assert client.ask("objects") == "ok none"
    assert server.call(lambda: server.scene.objects[server.robot.name]) == []


def test_collisions_name_the_object_the_arm_is_in(server: ServerThread, connect):
    client = connect(server)
    client.ask("degrees")
    client.ask(BOX)
    assert client.ask(f"j {INTO}") == "ok"  # unguarded: shown, and said
    reply = client.ask("collisions")
    assert re.fullmatch(r"ok (link_\w+~table,?)+", reply), reply
    client.ask("home")
    assert client.ask("collisions") == "ok none"


def test_guard_refuses_a_target_in_collision_and_nothing_moves(server: ServerThread, connect):
    client = connect(server)
    client.ask("degrees")
    client.ask(BOX)
    assert client.ask("guard") == "ok off"
    assert client.ask("guard on") == "ok"
    assert client.ask(f"j {REACH}") == "ok"
    reply = client.ask(f"j {INTO}")
    assert re.fullmatch(r"error: link_\w+ would hit table at the target", reply), reply
    assert client.ask("where") == f"ok {REACH}"
    assert client.ask(f"j {BEYOND}") == "ok"


def test_guarded_motion_refuses_a_path_through_the_box_before_it_starts(
    server: ServerThread, connect
):
    client = connect(server)
    client.ask("degrees")
    client.ask(BOX)
    client.ask(f"j {BEYOND}")
    for line in ("guard on", "motion on", "speed 100"):
        assert client.ask(line) == "ok"
    # Both ends are free; the way from -90 to 180 passes +90, through the box.
    reply = client.ask(f"j {THROUGH}")
    match = re.fullmatch(r"error: link_\w+ would hit table at (\d+)% of the move", reply)
    assert match and 50 < int(match.group(1)) < 80, reply
    assert client.ask("status") == "ok idle"
    assert client.ask("where") == f"ok {BEYOND}"
    assert client.ask(f"j {REACH}") == "ok"  # a free path goes


def test_guard_covers_moveto_and_the_whole_movel_line(server: ServerThread, connect):
    client = connect(server)
    client.ask("degrees")
    client.ask(BOX)
    poses = {}
    for name, q in (("into", INTO), ("left", "70,60,0,0,0,0,0"), ("right", "110,60,0,0,0,0,0")):
        assert client.ask(f"j {q}") == "ok"  # guard off: anywhere
        poses[name] = client.ask("pose")[3:]
    assert client.ask(f"j {REACH}") == "ok"
    assert client.ask("guard on") == "ok"
    reply = client.ask(f"moveto {poses['into']}")  # the tool in the box
    assert re.fullmatch(r"error: link_\w+ would hit table at the target", reply), reply
    assert client.ask("where") == f"ok {REACH}"
    # 70 and 110 degrees round are free; the straight line between passes the box at 90.
    assert client.ask("j 70,60,0,0,0,0,0") == "ok"
    reply = client.ask(f"movel {poses['right']}")
    assert re.fullmatch(r"error: .*link_\w+ would hit table.*", reply), reply
    assert client.ask("where") == "ok 70,60,0,0,0,0,0"
    assert client.ask("guard off") == "ok"
    assert client.ask(f"movel {poses['right']}") == "ok"  # the same line, unguarded, goes
    assert client.ask("collisions") == "ok none"


def test_rand_under_guard_draws_only_free_configurations(server: ServerThread, connect):
    client = connect(server)
    watcher = connect(server)
    client.ask("guard on")
    for _ in range(200):
        assert client.ask("rand") == "ok"
        assert watcher.ask("collisions") == "ok none"


def test_rand_blames_an_object_through_the_base_not_the_workcell(server, connect):
    # issue 30.6: a table that cuts link_s wherever the joints go
    client = connect(server)
    assert client.ask("object table box 1.2,0.8,0.05 0.6,0,0.3,0,0,0") == "ok"
    assert client.ask("collisions") == "ok link_s~table"
    assert client.ask("guard on") == "ok"
    before = client.ask("where")
    assert client.ask("rand") == (
        "error: no collision-free configuration of motoman_sia20d found in 1000 random "
        "draws: link_s touches table in every pose tried, a contact no joint undoes "
        "(an object through the robot's base? move or remove it)"
    )
    assert client.ask("where") == before
    assert client.ask("object table box 0.6,0.8,0.05 0.8,0,0.4,0,0,0") == "ok"  # the README's
    assert client.ask("collisions") == "ok none"
    assert client.ask("rand") == "ok"


@pytest.mark.parametrize(
    ("line", "error"),
    [
        ("object t box -1,1,1 0,0,0,0,0,0", "object: size -1 m is outside 1e-06..100 m"),
        ("object big box 1e308,1,1 0,0,0,0,0,0", "object: size 1e+308 m is outside 1e-06..100 m"),
        ("object far sphere 0.1 0,2e3,0", "object: y = 2000 m is outside -1000..1000 m"),
        ("object t box 1,nan,1 0,0,0,0,0,0", "bad number 'nan'"),
        ("object t cone 1 0,0,0", "unknown shape 'cone'; choose box, sphere or cylinder"),
        ("object t mesh /etc/passwd 0,0,0,0,0,0", "unknown shape 'mesh'"),
        ("object a/b sphere 1 0,0,0", "bad object name 'a/b'"),
        ("object my table box 1,1,1 0,0,0,0,0,0", "bad object name 'my table': one word"),
        ("object all sphere 1 0,0,0", "'all' is not an object name"),
        ("object t sphere 1", "sphere takes a size and a pose"),
        ("object t box 1,1 0,0,0,0,0,0", "needs 3 values, got 2"),
        ("guard maybe", "'maybe' is not on, off or plan"),
    ],
    ids=[
        "negative",
        "huge",
        "far",
        "nan",
        "cone",
        "mesh-file",
        "slash",
        "space",
        "all",
        "no-pose",
        "two-sizes",
        "guard",
    ],
)
def test_bad_object_lines_change_nothing(server: ServerThread, connect, line: str, error: str):
    client = connect(server)
    assert client.ask("object keep sphere 0.1 2,2,2") == "ok"
    reply = client.ask(line)
    assert reply.startswith("error: ") and error in reply, reply
    assert client.ask("objects") == "ok keep"


def test_too_many_objects(server: ServerThread, connect):
    client = connect(server)
    client.send("".join(f"object o{k} sphere 0.01 3,{k},0\n" for k in range(101)))
    replies = [client.read_line() for _ in range(101)]
    assert replies[:100] == ["ok"] * 100
    assert replies[100].startswith("error: ") and "100" in replies[100]
    assert len(client.ask("objects").split(",")) == 100


def test_the_observers_hear_of_collisions_as_they_change(server: ServerThread, connect):
    client = connect(server)
    client.ask("degrees")
    client.ask(BOX)
    client.ask(f"j {INTO}")
    client.ask("collisions")  # checks now
    client.ask("home")
    assert client.ask("collisions") == "ok none"
    told = server.call(lambda: list(server.scene.collisions))
    assert any(pairs and all(b == "table" for _, b in pairs) for _, pairs in told)
    assert told[-1] == (server.robot.name, [])


def test_rand_with_motion_under_guard_goes_along_a_free_path(connect):
    """With motion on the guard checks the path too: `rand` offers several free
    configurations and takes the first the arm reaches along a free path, so it says ok
    (the docs' workcell session), where one free target often had a blocked way to it."""
    clock = parse_clock("virtual")  # the moves take no wall time
    server = ServerThread(load_robot("motoman_sia20d"), ServerLimits(), clock=clock).start()
    try:
        client = connect(server)
        for line in ("degrees", "object table box 0.6,0.8,0.05 0.8,0,0.4,0,0,0", "guard on"):
            assert client.ask(line) == "ok", line
        assert client.ask("j 0,60,0,60,0,0,0") == "ok"
        assert client.ask("motion on") == "ok"
        for _ in range(30):
            assert client.ask("rand") == "ok"
            assert client.ask("collisions") == "ok none"
    finally:
        server.stop()
