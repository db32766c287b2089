"""Starting the page process (``--page-process``): forked at start, spawned on a restart.

At start the program forks the page process (``fork``) once it has loaded what both need
(Pinocchio, numpy, the session, the world's modules: some 0.45 s of a start) and before
it starts its loop, any thread of its own or any door: the child begins with all of it
loaded and only loads viser (``page_process``, ~0.15 s) while the program builds its
world and opens its doors, so the banner does not wait for a second load of the rest
(docs/page.md, "Start"). The fork takes nothing the page must not have: no loop, no
socket but its channel, its own session (a Ctrl-C is the program's to act on), stdin and
stdout on /dev/null.

A page process started again after a crash is ``spawn``ed fresh (``python -m
c2rviz.view.page_process FD``): by then the program has a running loop and threads, which
a fork would copy in whatever state they are.

This module loads the standard library alone.
"""

from __future__ import annotations

import contextlib
import os
import signal
import socket
import subprocess
import sys
import time
import traceback
from typing import Protocol

SCHEDULING = getattr(os, "SCHED_BATCH", None)
"""The page process's scheduling policy (Linux's ``SCHED_BATCH``): it keeps its fair share
of a CPU, but waking (a frame arrived, viser's thread has bytes to send) it never
preempts the task that runs, so on a CPU it shares with the command process it takes its
turns when the command loop waits or its slice ends instead of cutting into a reply.
In five alternated pairs of ``many_robots.py --robots 64 --page-process`` at load 8-11
a bystander's p99 was lower with it in four (medians 19.4 -> 11.7 ms), the page's frames
the same within the noise; ``run.py --tab --page-process``'s rows did not move beyond
theirs (docs/page.md)."""


class PageProcessHandle(Protocol):
    """What the program does with a page process: a ``subprocess.Popen`` or ``Forked``."""

    @property
    def pid(self) -> int: ...

    def poll(self) -> int | None: ...

    def wait(self, timeout: float | None = None) -> int: ...

    def kill(self) -> None: ...


Spawned = tuple[PageProcessHandle, socket.socket]
"""A page process and the program's end of its channel."""


class Forked:
    """A forked page process, handled as a ``subprocess.Popen`` is (``returncode``: its exit
    status, or minus the signal that ended it)."""

    def __init__(self, pid: int) -> None:
        self.pid = pid
        self.returncode: int | None = None

    def poll(self) -> int | None:
        if self.returncode is None:
            pid, status = os.waitpid(self.pid, os.WNOHANG)
            if pid == self.pid:
                self.returncode = os.waitstatus_to_exitcode(status)
        return self.returncode

    def wait(self, timeout: float | None = None) -> int:
        """Its exit status, once it ended (``subprocess.TimeoutExpired`` after ``timeout``)."""
        deadline = None if timeout is None else time.monotonic() + timeout
        while (code := self.poll()) is None:
            if deadline is not None and time.monotonic() > deadline:
                raise subprocess.TimeoutExpired(f"page process {self.pid}", timeout or 0.0)
            time.sleep(0.01)
        return code

    def kill(self) -> None:
        if self.poll() is None:
            os.kill(self.pid, signal.SIGKILL)


def fork() -> Spawned | None:
    """Fork a page process now (see the module docstring); None if it cannot be (the
    program spawns one when the page opens, and says why if that fails too)."""
    try:
        ours, theirs = socket.socketpair()
    except OSError:
        return None
    sys.stdout.flush()
    sys.stderr.flush()
    try:
        pid = os.fork()
    except OSError:
        ours.close()
        theirs.close()
        return None
    if pid == 0:  # the page process: it never returns into the program
        code = 1
        try:
            ours.close()
            os.setsid()
            null = os.open(os.devnull, os.O_RDWR)
            os.dup2(null, 0)
            os.dup2(null, 1)
            behind_commands(0)
            from .page_process import run

            code = run(theirs)
        except BaseException:
            traceback.print_exc()
        finally:
            os._exit(code)
    theirs.close()
    return Forked(pid), ours


def spawn() -> Spawned:
    """Start a fresh page process; it and our end of its channel. It loads viser and waits
    for its ``hello`` meanwhile.

    Raises:
        OSError: it cannot be started.
    """
    ours, theirs = socket.socketpair()
    try:
        process = subprocess.Popen(
            [sys.executable, "-m", "c2rviz.view.page_process", str(theirs.fileno())],
            pass_fds=(theirs.fileno(),),
            stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL,
            start_new_session=True,  # a Ctrl-C is ours to act on: we stop it in order
        )
    except OSError:
        ours.close()
        raise
    finally:
        theirs.close()
    behind_commands(process.pid)  # its one thread yet: those it starts inherit it
    return process, ours


def close(spawned: Spawned) -> None:
    """End a page process that got no ``hello``: it sees its channel close and exits. One
    handed to a ``PageLink`` (its channel taken, then closed by it) is left alone."""
    process, ours = spawned
    if ours.fileno() == -1:
        return
    ours.close()
    try:
        process.wait(timeout=2.0)
    except subprocess.TimeoutExpired:
        process.kill()
        process.wait()


def behind_commands(pid: int) -> None:
    """Put process ``pid`` (0: this one), a page process that has one thread yet, under
    ``SCHEDULING``; the threads it starts later (viser's, a math library's pool) inherit
    it. Nothing where the policy does not exist or may not be set."""
    if SCHEDULING is not None:
        with contextlib.suppress(OSError):
            os.sched_setscheduler(pid, SCHEDULING, os.sched_param(0))
