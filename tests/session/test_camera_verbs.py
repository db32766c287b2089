"""Logical cameras through the real server: the verbs, what a camera sees (frustum,
occlusion, its frame, units), noise from the seed, `watch` lines at the camera's rate on
virtual time, and bad input that changes nothing."""

from __future__ import annotations

import re
import time

import numpy as np
import pytest
from support import Client, ServerLimits, ServerThread, load_robot
from watch_support import is_reply

from c2rviz.world.cameras import MAX_CAMERAS
from c2rviz.world.virtual_clock import VirtualClock

# Looking straight down (pitch 90 deg turns +x onto -z) from 1 m above the origin.
DOWN = "camera top 0,0,1,0,1.5707963267948966,0"
PART = "part p1 box 0.03,0.03,0.03 0.2,0.1,0.015,0,0,0 type=battery"


@pytest.fixture
def server():
    thread = ServerThread(load_robot("fanuc_lrmate200id"), ServerLimits(), clock=VirtualClock())
    thread.start()
    client = Client(thread.host, thread.port)
    try:
        yield thread, client
    finally:
        client.close()
        thread.stop()


def _values(text: str) -> list[float]:
    return [float(v) for v in text.split(",")]


def test_a_camera_sees_a_part_in_its_frame(server) -> None:
    _, client = server
    assert client.ask(PART) == "ok"
    assert client.ask(DOWN) == "ok"
    reply = client.ask("camera top")
    name, kind, pose = reply.removeprefix("ok ").split(":")
    assert (name, kind) == ("p1", "battery")
    # In the camera's frame: 0.985 m ahead (+x); looking down, its z points along the
    # world's +x, and its y stays the world's +y.
    np.testing.assert_allclose(_values(pose)[:3], [0.985, 0.1, 0.2], atol=1e-9)
    assert client.ask("cameras").startswith("ok top:0,0,1,0,1.570796327,0:1.047197551,")


def test_degrees_for_poses_and_fields_of_view(server) -> None:
    _, client = server
    assert client.ask("degrees") == "ok"
    assert client.ask(PART) == "ok"
    assert client.ask("camera top 0,0,1,0,90,0 20,20,2") == "ok"  # 10 deg each side
    assert client.ask("camera top") == "ok none"  # p1 is 12.6 deg off the axis
    assert client.ask("camera top 0,0,1,0,90,0 30,30,2") == "ok"
    reply = client.ask("camera top")
    assert reply.startswith("ok p1:battery:")
    assert _values(reply.split(":")[2])[4] == pytest.approx(-90.0)  # pitch, in degrees
    assert client.ask("cameras") == "ok top:0,0,1,0,90,0:30,30,2:10"


def test_the_range_and_occlusion_by_an_object(server) -> None:
    _, client = server
    assert client.ask(PART) == "ok"
    assert client.ask("camera side 0.2,-1,0.015,0,0,1.5707963267948966 1,1,1") == "ok"
    assert client.ask("camera side") == "ok none"  # 1.1 m away, the range is 1 m
    assert client.ask("camera side 0.2,-1,0.015,0,0,1.5707963267948966 1,1,1.2") == "ok"
    assert client.ask("camera side").startswith("ok p1:battery:")
    assert client.ask("object wall box 0.3,0.02,0.2 0.2,-0.5,0.1,0,0,0") == "ok"
    assert client.ask("camera side") == "ok none"
    assert client.ask("object wall remove") == "ok"
    assert client.ask("camera side").startswith("ok p1:battery:")


def test_a_part_without_a_type_is_reported_by_its_shape(server) -> None:
    _, client = server
    assert client.ask("part ball sphere 0.02 0,0,0.02") == "ok"
    assert client.ask(DOWN) == "ok"
    assert client.ask("camera top").startswith("ok ball:sphere:")


def test_noise_repeats_with_the_seed(server) -> None:
    thread, client = server
    assert client.ask(PART) == "ok"
    assert client.ask(DOWN) == "ok"
    exact = client.ask("camera top")

    def noisy(seed: int) -> list[str]:
        thread.call(lambda: setattr(thread.services, "rng", np.random.default_rng(seed)))
        assert client.ask("camera top noise 0.01,0.02") == "ok"
        return [client.ask("camera top") for _ in range(3)]

    first = noisy(3)
    assert noisy(3) == first
    assert noisy(4) != first
    assert len(set(first)) == 3 and exact not in first
    assert client.ask("camera top noise 0,0") == "ok"
    assert client.ask("camera top") == exact


def test_remove_and_list(server) -> None:
    _, client = server
    assert client.ask("cameras") == "ok none"
    assert client.ask(DOWN) == "ok"
    assert client.ask("camera top remove") == "ok"
    assert client.ask("cameras") == "ok none"
    assert client.ask("camera top") == "error: no camera named 'top' (cameras: none)"


BAD = [
    ("camera top 0,0,1,0,0,0 0,45,2", "h_fov = 0 deg must be above 0 and below 180 deg"),
    ("camera top 0,0,1,0,0,0 -1,0.5,2", "h_fov = -57.2958 deg must be above 0"),
    ("camera top 0,0,1,0,0,0 1,3.1415927,2", "v_fov = 180 deg must be above 0"),
    ("camera top 0,0,1,0,0,0 1,1,-1", "range = -1 m must be above 0 and at most 100 m"),
    ("camera top 0,0,1,0,0,0 1,1,1e308", "range = 1e+308 m must be above 0"),
    ("camera top 0,0,1e308,0,0,0", "z = 1e+308 m is outside"),
    ("camera top 0,0,1,0,0,0 1e308,1,1", "h_fov = "),
    ("camera top 0,0,1", "needs 6 values, got 3"),
    ("camera top 0,0,1,0,0,0 1,1", "needs 3 values, got 2"),
    ("camera top 0,0,1,0,0,0 1,1,1 extra", "takes a pose and maybe h_fov,v_fov,range"),
    ("camera nope", "no camera named 'nope'"),
    ("camera nope remove", "no camera named 'nope'"),
    ("camera nope rate 5", "no camera named 'nope'"),
    ("camera top rate -1", "rate -1 Hz is outside 0..100"),
    ("camera top rate 1e308", "rate 1e+308 Hz is outside"),
    ("camera top noise -0.1,0", "noise takes SIGMA_M in 0..1 m"),
    ("camera top noise 0.1,4", "angle noise 4 is above half a turn"),
    ("camera bad/name", "bad camera name"),
    ("camera", "needs a camera name"),
]


@pytest.mark.parametrize(("line", "message"), BAD, ids=[line for line, _ in BAD])
def test_bad_input_is_refused_and_changes_nothing(server, line: str, message: str) -> None:
    _, client = server
    assert client.ask(PART) == "ok"
    assert client.ask(DOWN) == "ok"
    before = (client.ask("cameras"), client.ask("camera top"))
    reply = client.ask(line)
    assert reply.startswith("error: ") and message in reply, reply
    assert (client.ask("cameras"), client.ask("camera top")) == before


def test_the_number_of_cameras_is_limited(server) -> None:
    _, client = server
    for i in range(MAX_CAMERAS):
        assert client.ask(f"camera c{i} 0,0,{i},0,0,0") == "ok"
    reply = client.ask("camera extra 0,0,1,0,0,0")
    assert (
        reply
        == f"error: the world already holds {MAX_CAMERAS} cameras, its limit; remove one first"
    )
    assert client.ask("camera c0 1,1,1,0,0,0") == "ok"  # moving one is no new camera


CAMERA_LINE = re.compile(r"camera (\w+) (\d+\.\d{6}) (\S+)")


def test_watch_carries_camera_lines_at_its_rate_on_virtual_time(server) -> None:
    _, client = server
    assert client.ask(PART) == "ok"
    assert client.ask(DOWN) == "ok"
    assert client.ask("camera top rate 4") == "ok"
    seen: list[str] = []
    client.send("watch\n")
    client.send("sleep 1\n")
    replies = 0
    while replies < 2:
        line = client.read_line()
        if is_reply(line):
            replies += 1
        elif line.startswith("camera "):
            seen.append(line)
    stamps = []
    for line in seen:
        match = CAMERA_LINE.fullmatch(line)
        assert match is not None, line
        assert match.group(1) == "top" and match.group(3).startswith("p1:battery:")
        stamps.append(float(match.group(2)))
    # The first at once, then every 0.25 s of the world's clock while the sleep lasts (the
    # one at its end, t = 1, was set after the sleep's timer: it comes after the reply).
    start = stamps[0]
    assert [round(t - start, 6) for t in stamps] == [0.0, 0.25, 0.5, 0.75]
    assert CAMERA_LINE.fullmatch(client.read_line()).group(2) == f"{start + 1:.6f}"


def test_rate_zero_keeps_a_camera_out_of_watch(server) -> None:
    _, client = server
    assert client.ask(DOWN) == "ok"
    assert client.ask("camera top rate 0") == "ok"
    client.send("watch\n")
    client.send("sleep 1\n")
    replies = 0
    while replies < 2:
        line = client.read_line()
        assert not line.startswith("camera "), line
        replies += is_reply(line)


def test_a_camera_alone_does_not_move_virtual_time(server) -> None:
    thread, client = server
    clock = thread.world.clock
    assert client.ask(DOWN) == "ok"
    assert client.ask("camera top rate 4") == "ok"
    start = thread.call(clock.now)
    client.send("watch\n")
    assert client.read_line() == "ok"
    lines = [client.read_line(), client.read_line()]
    assert f"camera top {start:.6f} none" in lines, lines
    # Only watching: nobody holds the clock, and the camera is parked, not ticking alone.
    assert thread.call(lambda: (clock.now(), clock.next_timer())) == (start, None)
    # A command wakes it: a sleep's half second carries its lines again.
    client.send("sleep 0.5\n")
    seen = []
    while not is_reply(line := client.read_line()):
        seen.append(line)
    assert line == "ok"
    assert [s for s in seen if s.startswith("camera")] == [f"camera top {start + 0.25:.6f} none"]


def test_a_blackout_hides_everything_until_its_time(server) -> None:
    thread, client = server
    world = thread.world
    assert client.ask(PART) == "ok"
    assert client.ask(DOWN) == "ok"
    thread.call(lambda: world.cameras.blackout("top", world.clock.now() + 0.5))
    assert client.ask("camera top") == "ok none"
    assert client.ask("sleep 0.5") == "ok"
    assert client.ask("camera top").startswith("ok p1:battery:")


def test_fault_blackout_darkens_a_camera_for_its_time_on_the_world_clock(server) -> None:
    _, client = server
    assert client.ask(PART) == "ok"
    assert client.ask(DOWN) == "ok"
    assert client.ask("fault blackout top 2") == "ok"
    assert client.ask("camera top") == "ok none"
    assert client.ask("sleep 1.9") == "ok"
    assert client.ask("camera top") == "ok none"
    assert client.ask("sleep 0.2") == "ok"
    assert client.ask("camera top").startswith("ok p1:battery:")


def test_fault_blackout_until_cleared_and_scheduled(server) -> None:
    _, client = server
    assert client.ask(PART) == "ok"
    assert client.ask(DOWN) == "ok"
    assert client.ask("fault blackout top") == "ok"
    assert client.ask("sleep 100") == "ok"
    assert client.ask("camera top") == "ok none"
    assert client.ask("fault clear blackout") == "ok"
    assert client.ask("camera top").startswith("ok p1:battery:")
    assert client.ask("fault after 1 blackout top 1") == "ok"
    assert client.ask("camera top").startswith("ok p1:battery:")
    assert client.ask("sleep 1.5") == "ok"
    assert client.ask("camera top") == "ok none"
    assert client.ask("sleep 1") == "ok"
    assert client.ask("camera top").startswith("ok p1:battery:")


@pytest.mark.parametrize(
    ("line", "error"),
    [
        ("fault blackout nope", "error: no camera named 'nope' (cameras: top)"),
        ("fault blackout top 0", "error: fault: blackout S '0' is not a time in (0, 1e+06] s"),
        ("fault blackout top -1", "error: fault: blackout S '-1' is not a time"),
        ("fault blackout", "error: fault: blackout needs a CAMERA"),
        ("fault blackout top 1 2", "error: fault: blackout needs a CAMERA"),
    ],
)
def test_a_bad_blackout_is_refused_and_changes_nothing(server, line, error) -> None:
    _, client = server
    assert client.ask(PART) == "ok"
    assert client.ask(DOWN) == "ok"
    assert client.ask(line).startswith(error)
    assert client.ask("camera top").startswith("ok p1:battery:")


def test_watch_and_a_recording_together_do_not_spin_virtual_time(tmp_path) -> None:
    thread = ServerThread(
        load_robot("fanuc_lrmate200id"), ServerLimits(), clock=VirtualClock(), record_dir=tmp_path
    )
    thread.start()
    client = Client(thread.host, thread.port)
    try:
        clock = thread.world.clock
        assert client.ask(DOWN) == "ok"
        assert client.ask("record take").startswith("ok recording take")
        start = thread.call(clock.now)
        client.send("watch\n")
        assert client.read_line() == "ok"
        # Only watching: every feed (the watch's, the bag's) parks once nothing else is
        # pending, instead of keeping the other's timers alive.
        for _ in range(2000):
            if thread.call(clock.next_timer) is None:
                break
            time.sleep(0.005)
        assert thread.call(clock.next_timer) is None
        assert thread.call(clock.now) - start < 1.0
        client.send("record stop\n")
        while not is_reply(line := client.read_line()):
            pass
        assert line.startswith("ok")
    finally:
        client.close()
        thread.stop()
