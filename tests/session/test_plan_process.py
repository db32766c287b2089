"""A plan in a child process (``session.plan_process``): its answer and its errors come back
whole, and a cancelled plan's process is killed at once."""

from __future__ import annotations

import os
import threading
from pathlib import Path

import numpy as np
import pytest

from c2rviz.planning import NoPathFound
from c2rviz.planning.errors import STOPPED, Cancel, PlanCancelled
from c2rviz.session import plan_process
from c2rviz.session.plan_process import ParentGone, run_forked


def test_the_answer_comes_back_from_another_process() -> None:
    parent = os.getpid()
    pid, rows = run_forked(lambda: (os.getpid(), np.eye(3)))
    assert pid != parent
    np.testing.assert_array_equal(rows, np.eye(3))
    assert not plan_process.CHILD


def test_an_error_comes_back_with_its_fields_and_message() -> None:
    def fails() -> None:
        raise NoPathFound(1.5, 1234)

    with pytest.raises(NoPathFound, match=r"^no path found in 1\.5 s \(1234 states\)$") as caught:
        run_forked(fails)
    assert (caught.value.timeout_s, caught.value.states) == (1.5, 1234)


def test_a_child_that_dies_without_an_answer_is_an_error() -> None:
    with pytest.raises(RuntimeError, match="ended without an answer"):
        run_forked(lambda: os._exit(3))


def test_a_cancelled_plans_process_is_killed(tmp_path: Path) -> None:
    cancel = Cancel()
    started = tmp_path / "pid"

    def search() -> None:
        (tmp_path / "pid.part").write_text(str(os.getpid()))
        (tmp_path / "pid.part").rename(started)  # started: tell the test who
        threading.Event().wait(600)  # a long search

    caught: list[BaseException] = []

    def parent() -> None:
        try:
            run_forked(search, cancel)
        except BaseException as exc:
            caught.append(exc)

    waiting = threading.Thread(target=parent)
    waiting.start()
    while not started.exists() and waiting.is_alive():
        threading.Event().wait(0.01)
    child = int(started.read_text())
    cancel.set(STOPPED)
    waiting.join(60)
    assert not waiting.is_alive()
    assert len(caught) == 1 and isinstance(caught[0], PlanCancelled), caught
    with pytest.raises(ProcessLookupError):  # killed and reaped
        os.kill(child, 0)


def test_a_childs_cancel_flag_is_its_parent_going() -> None:
    flag = ParentGone()
    assert not flag()
    assert run_forked(lambda: (plan_process.CHILD, ParentGone()())) == (True, False)


def test_a_child_holds_none_of_the_servers_sockets() -> None:
    import socket

    listening = socket.socket()
    try:
        listening.bind(("127.0.0.1", 0))
        listening.listen()
        number = listening.fileno()

        def is_open() -> bool:
            try:
                os.fstat(number)
            except OSError:
                return False
            return True

        assert is_open() and run_forked(is_open) is False
    finally:
        listening.close()
