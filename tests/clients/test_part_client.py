"""The clients' part, goal and score methods: their lines, their readings, arguments
refused before anything is sent, and both clients against a server."""

from __future__ import annotations

import asyncio

import pytest

from c2rviz import AsyncClient, CommandError
from c2rviz.clients.errors import ArgumentError
from c2rviz.clients.task_calls import PartState, Score, add_part, goal, read_parts, read_score


def test_part_lines():
    assert add_part("p1", "box", (0.03, 0.03, 0.03), (0.5, 0.0, 0.015, 0.0, 0.0, 0.0)).line == (
        "part p1 box 0.03,0.03,0.03 0.5,0.0,0.015,0.0,0.0,0.0"
    )
    assert add_part("s", "sphere", 0.02, (0.4, 0.0, 0.02), "ball", (1.0, 0.0, 0.5)).line == (
        "part s sphere 0.02 0.4,0.0,0.02 type=ball color=1.0,0.0,0.5"
    )
    assert goal("type=cube", (0.5, 0.0, 0.015, 0.0, 0.0, 0.0), (0.01, 2.0)).line == (
        "goal type=cube 0.5,0.0,0.015,0.0,0.0,0.0 0.01,2.0"
    )


@pytest.mark.parametrize(
    ("call", "problem"),
    [
        (lambda: add_part("p1", "cone", 1, (0, 0, 0, 0, 0, 0)), "'cone' is not one of"),
        (lambda: add_part("p1", "box", (1, 1), (0, 0, 0, 0, 0, 0)), "needs 3 size values"),
        (lambda: add_part("p1", "box", (1, 1, 1), (0, 0, 0)), "needs 6 values"),
        (lambda: add_part("p1", "box", (1e308,) * 3, (0, 0, 0, 0, 0, 0)), "size"),
        (lambda: goal("p1", (0, 0, 0, 0, 0, 0), (0.01,)), "needs 2 values"),
    ],
)
def test_bad_part_arguments_are_refused_before_sending(call, problem):
    with pytest.raises(ArgumentError, match=problem):
        call()


def test_reading_parts_and_the_score():
    assert read_parts("ok none") == {}
    assert read_parts("ok p1:0.4,0,0.2,0,0,0:resting on table;p2:1,2,3,0,0,0.5:held") == {
        "p1": PartState((0.4, 0, 0.2, 0, 0, 0), "resting on table"),
        "p2": PartState((1, 2, 3, 0, 0, 0.5), "held"),
    }
    assert read_score("ok no goals") == Score(0, 0, ())
    assert read_score("ok 1/3 met; p2 0.0 mm 0.2 rad off; type=gear missing") == Score(
        1, 3, ("p2 0.0 mm 0.2 rad off", "type=gear missing")
    )


@pytest.mark.c2rviz(clock="virtual")
def test_the_client_places_parts_and_scores_them(c2rviz):
    c2rviz.add_part("p1", "box", (0.05, 0.05, 0.05), (0.5, 0.5, 0.025, 0, 0, 0), kind="cube")
    c2rviz.add_part("p2", "sphere", 0.02, (0.5, -0.5, 0.02))
    where = c2rviz.part("p1")
    assert where.pose == pytest.approx((0.5, 0.5, 0.025, 0, 0, 0))
    assert set(c2rviz.parts()) == {"p1", "p2"}
    c2rviz.goal("p1", (0.5, 0.5, 0.025, 0, 0, 0))
    c2rviz.goal("type=gear", (0, 0, 0, 0, 0, 0))
    assert c2rviz.score() == Score(1, 2, ("type=gear missing",))
    with pytest.raises(CommandError, match="no part named 'p9'"):
        c2rviz.goal("p9", (0, 0, 0, 0, 0, 0))
    c2rviz.remove_goals()
    assert c2rviz.score() == Score(0, 0, ())
    c2rviz.remove_part("p2")
    assert set(c2rviz.parts()) == {"p1"}
    c2rviz.remove_parts()
    assert c2rviz.parts() == {}


def test_the_async_client_places_parts(c2rviz_server):
    async def main() -> tuple[dict[str, PartState], Score]:
        async with AsyncClient(c2rviz_server.host, c2rviz_server.port) as robot:
            await robot.add_part("a", "cylinder", (0.01, 0.05), (0.4, 0.1, 0.025, 0, 0, 0))
            await robot.goal("a", (0.4, 0.1, 0.025, 0, 0, 0), (0.001, 0.01))
            found = await robot.parts()
            score = await robot.score()
            await robot.remove_parts()
            return found, score

    found, score = asyncio.run(main())
    assert list(found) == ["a"] and found["a"].pose[:3] == pytest.approx((0.4, 0.1, 0.025))
    assert score == Score(1, 1, ())


@pytest.mark.c2rviz(clock="virtual")
def test_the_client_places_cameras_and_reads_what_they_see(c2rviz):
    c2rviz.degrees()
    c2rviz.add_part("p1", "box", (0.04, 0.04, 0.04), (1, 0, 0.02, 0, 0, 0), kind="battery")
    c2rviz.add_camera("top", (1, 0, 1.5, 0, 90, 0))
    seen = c2rviz.camera("top")
    assert [(s.name, s.type) for s in seen] == [("p1", "battery")]
    assert seen[0].pose[:3] == pytest.approx((1.48, 0, 0))
    c2rviz.add_camera("side", (1, -1, 0.02, 0, 0, 90), (60, 45, 2))
    c2rviz.camera_rate("top", 2)
    c2rviz.camera_noise("top", 0.001, 0.1)
    listed = c2rviz.cameras()
    assert listed["top"].rate == 2 and listed["side"].fov == (60, 45, 2)
    with pytest.raises(CommandError):
        c2rviz.add_camera("bad", (0, 0, 1, 0, 0, 0), (0, 45, 2))
    c2rviz.remove_camera("side")
    assert list(c2rviz.cameras()) == ["top"]
