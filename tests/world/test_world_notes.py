"""What the world's observers hear of a line: ``note``/``replied`` per line and ``taken`` for a
run of lines taken at once tell each observer the same, and only those that listen."""

from __future__ import annotations

from collections.abc import Sequence

import pytest
from support import load_robot

from c2rviz.world.observer import Observer, RecordingScene, hears
from c2rviz.world.world import World


class Both(Observer):
    """Hears commands and replies, in order."""

    def __init__(self) -> None:
        self.heard: list[tuple[str, ...]] = []

    def on_command(self, source: str, line: str, accepted: bool) -> None:
        self.heard.append(("command", source, line, str(accepted)))

    def on_reply(self, source: str, line: str, reply: str) -> None:
        self.heard.append(("reply", source, line, reply))


class Replies(Observer):
    def __init__(self) -> None:
        self.heard: list[tuple[str, str, str]] = []

    def on_reply(self, source: str, line: str, reply: str) -> None:
        self.heard.append((source, line, reply))


class Batches(Observer):
    """Takes a run of lines at once."""

    def __init__(self) -> None:
        self.lines: list[str] = []
        self.calls = 0

    def on_command(self, source: str, line: str, accepted: bool) -> None:
        self.lines.append(line)
        self.calls += 1

    def on_commands(self, source: str, lines: Sequence[str]) -> None:
        self.lines.extend(lines)
        self.calls += 1


class Deaf(Observer):
    def on_command(self, source: str, line: str, accepted: bool) -> None:
        raise AssertionError("removed: hears nothing")


@pytest.fixture(scope="module")
def robot():
    return load_robot("motoman_sia20d")


def _observers() -> list[Observer]:
    return [Both(), Replies(), Batches(), RecordingScene()]


def _heard(observers: Sequence[Observer]) -> list[object]:
    return [getattr(o, "heard", None) or getattr(o, "lines", None) or o.commands for o in observers]


LINES = ["joints 0,0,0,0,0,0,0", "j 0.1,0,0,0,0,0,0", "joints 0.2,0,0,0,0,0,0"]


def test_a_run_taken_at_once_is_heard_as_line_by_line(robot) -> None:
    one_by_one, at_once = _observers(), _observers()
    world = World(robot)
    world.add_observers(one_by_one)
    for line in LINES:
        world.note("tcp a", line, True)
        world.replied("tcp a", line, "ok")
    world.remove_observer(one_by_one[0])  # (also: a removed observer hears no more)
    world.observers = [o for o in world.observers if o not in one_by_one]
    world.add_observers(at_once)
    world.taken("tcp a", LINES, "ok")
    assert _heard(at_once) == _heard(one_by_one)
    assert at_once[0].heard[:2] == [
        ("command", "tcp a", LINES[0], "True"),
        ("reply", "tcp a", LINES[0], "ok"),
    ]
    assert at_once[2].calls == 1  # the whole run in one call


def test_only_observers_that_listen_are_told_and_a_new_list_counts(robot) -> None:
    deaf = Deaf()
    world = World(robot)
    world.add_observers([deaf])
    assert hears(deaf) == "commands" and hears(Observer()) == ""
    world.observers = [o for o in world.observers if o is not deaf]  # assigned, not edited
    world.note("tcp a", "where", True)
    world.taken("tcp a", LINES, "ok")
    batches = Batches()
    world.observers = [*world.observers, batches]
    world.note("tcp a", "where", True)
    assert batches.lines == ["where"]
