"""A plan on the plan lane: ``plan_job``, on its thread and then in a forked child.

OMPL's Python bindings keep the interpreter's lock through ``solve``: between its
calls back into Python its C++ holds it, and as a search's trees grow (hundreds of
thousands of states) their rebuilds hold it for tens to hundreds of milliseconds,
during which no other thread of the server runs: not the event loop, not the IK.
So a plan that searches long (``plan_job``) goes on in a child forked
from the plan lane's thread: the child has the request (the robot's collision
model, the workcell, the other robots) as the parent had it, at no cost of
copying, searches with its own interpreter lock, and sends back the result (or
the error) through a pipe, pickled. The parent's thread
waits on that pipe, looking at the plan's ``Cancel`` meanwhile: when it is set
(``stop``, the client gone, a newer plan) the child is killed at once.

A child never outlives its search by long: it exits when done, its parent kills it
when cancelled, and it stops searching if its parent is gone (the plan's cancel
flag in the child is "my parent changed").
"""

from __future__ import annotations

import contextlib
import dataclasses
import functools
import math
import os
import pickle
import select
import signal
import threading
import time
import warnings
from collections.abc import Callable
from typing import Any, TypeVar

from ..planning.errors import Cancel, NoPathFound, NoWayAround, PlanCancelled
from ..planning.guarded_move import CheckedMove, MoveChecker, MoveRequest
from ..planning.ompl_planner import fork_lock

T = TypeVar("T")

POLL_S = 0.01  # [s] how often a waiting parent looks at the plan's cancel flag
_PLAN_LANE = threading.local()  # a plan lane thread's own move checker
THREAD_S = 0.25  # [s] a plan's search on its thread before the rest goes to a process
GRACE_S = 10.0  # [s] a plan's process answers this long after its time limit, or is killed
CHILD = False  # True in a plan's child process
MAX_FD = 1 << 20  # descriptors a child closes (above it: none open here)


class ParentGone(Cancel):
    """A child's cancel flag: set once its parent process has gone."""

    def __init__(self) -> None:
        super().__init__()
        self._parent = os.getppid()

    def __call__(self) -> bool:
        if not super().__call__() and os.getppid() != self._parent:
            self.set("the server stopped")
        return super().__call__()


def in_child(request: MoveRequest) -> MoveRequest:
    """``request`` as a plan's child should run it: with the child's own cancel flag (the
    parent's cannot reach it); unchanged in the server's own process."""
    return dataclasses.replace(request, cancel=ParentGone()) if CHILD else request


def plan_job(asked: MoveRequest, processes: bool) -> CheckedMove:
    """A plan on its lane's thread: the first ``THREAD_S`` of search there (most plans
    end within it), the rest (``processes``) in a forked child, where OMPL's C++ holds
    no lock of the server's (see ``plan_process``). A seeded search starts again the
    same in the child, so it finds the same path as one long search."""
    if not processes or asked.timeout_s <= THREAD_S:
        return plan_checked(asked)
    began = time.perf_counter()
    try:
        return plan_checked(dataclasses.replace(asked, timeout_s=THREAD_S))
    except (NoPathFound, NoWayAround) as exc:
        searched = exc.__cause__ if isinstance(exc, NoWayAround) else exc
        if not isinstance(searched, NoPathFound):
            raise
        states = searched.states
    rest = dataclasses.replace(asked, spent=(time.perf_counter() - began, states))
    return run_forked(
        functools.partial(plan_checked, rest), asked.cancel, asked.timeout_s + GRACE_S
    )


def plan_checked(asked: MoveRequest) -> CheckedMove:
    """``MoveChecker.check`` on the plan lane (in its own process, or on a plan lane
    thread with that thread's own checker)."""
    checker = getattr(_PLAN_LANE, "moves", None)
    if checker is None:
        checker = _PLAN_LANE.moves = MoveChecker()
    return checker.check(in_child(asked))


def run_forked(
    fn: Callable[[], T], cancel: Cancel | None = None, deadline_s: float = math.inf
) -> T:
    """``fn()`` run in a forked child; its result, or its exception raised here.

    Args:
        fn: What the child runs (its result and errors must pickle).
        cancel: Kills the child when set.
        deadline_s: Kills the child if it has not answered within this [s].

    Raises:
        PlanCancelled: ``cancel`` was set while the child ran (it was killed).
        RuntimeError: the child died, or did not answer within ``deadline_s``.
    """
    read_fd, write_fd = os.pipe()
    with fork_lock(), warnings.catch_warnings():  # (no thread draws OMPL's seeds meanwhile)
        warnings.simplefilter("ignore", DeprecationWarning)  # (3.12: fork with threads)
        pid = os.fork()
    if pid == 0:  # the child: run, answer, leave without running the parent's cleanups
        global CHILD
        CHILD = True
        status = 0
        try:
            _alone(write_fd)
            with os.fdopen(write_fd, "wb") as out:
                out.write(_answer(fn))
        except BaseException:
            status = 1
        os._exit(status)
    os.close(write_fd)
    try:
        data = _read(read_fd, pid, cancel, time.monotonic() + deadline_s)
    finally:
        os.close(read_fd)
        _reap(pid)
    answer: tuple[str, Any] = pickle.loads(data) if data else ("error", portable_error(_lost()))
    if answer[0] == "error":
        raise rebuilt_error(answer[1])
    result: T = answer[1]
    return result


def _alone(keep: int) -> None:
    """In the child: close every descriptor but stdio and ``keep`` (the server's sockets
    must close when the server closes them, not when a plan ends), and take the default
    signal handlers (the server's belong to its event loop, which does not run here)."""
    os.closerange(3, keep)
    os.closerange(keep + 1, MAX_FD)
    with contextlib.suppress(ValueError, OSError):
        signal.set_wakeup_fd(-1)
        for number in (signal.SIGINT, signal.SIGTERM):
            signal.signal(number, signal.SIG_DFL)


def _answer(fn: Callable[[], Any]) -> bytes:
    try:
        answer: tuple[str, Any] = ("ok", fn())
    except BaseException as exc:
        answer = ("error", portable_error(exc))
    try:
        return pickle.dumps(answer)
    except Exception as exc:  # an answer that does not pickle: say so
        return pickle.dumps(("error", portable_error(RuntimeError(f"plan answer: {exc!r}"))))


def _read(fd: int, pid: int, cancel: Cancel | None, deadline: float) -> bytes:
    chunks: list[bytes] = []
    while True:
        ready, _, _ = select.select([fd], [], [], POLL_S)
        if ready:
            chunk = os.read(fd, 1 << 20)
            if not chunk:
                return b"".join(chunks)
            chunks.append(chunk)
        elif cancel is not None and cancel():
            os.kill(pid, signal.SIGKILL)
            raise PlanCancelled(cancel.why)
        elif time.monotonic() > deadline:
            os.kill(pid, signal.SIGKILL)
            raise RuntimeError("the plan's process did not answer in time (killed)")


def _reap(pid: int) -> None:
    with contextlib.suppress(ChildProcessError):
        os.waitpid(pid, 0)


def _lost() -> RuntimeError:
    return RuntimeError("the plan's process ended without an answer (see the server log)")


def portable_error(
    exc: BaseException,
) -> tuple[type[BaseException], tuple[Any, ...], dict[str, Any]]:
    """An exception as its class, args and attributes (our errors' constructors take
    their fields, not their message, so pickle's own way would not rebuild them)."""
    try:
        fields = dict(vars(exc))
        pickle.dumps(fields)
    except Exception:
        fields = {}
    return type(exc), exc.args, fields


def rebuilt_error(
    value: tuple[type[BaseException], tuple[Any, ...], dict[str, Any]],
) -> BaseException:
    """The exception ``portable_error`` took apart, raised again in this process."""
    cls, args, fields = value
    exc = cls.__new__(cls)
    exc.args = args
    exc.__dict__.update(fields)
    return exc
