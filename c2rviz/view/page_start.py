"""Starting the page process (``--page-process``) as early as the program can.

The page process spends most of its start loading Python (viser, Pinocchio, numpy,
the session: some 0.5 s here), and so does the program. ``spawn`` starts it; the
program calls ``early`` first thing, before its own heavy imports, so both load side by
side on two cores and the banner waits only for the page's own set-up (docs/page.md).

``early`` only peeks: ``--page-process`` among the arguments, or ``page_process = on``
in ``[options]`` of the ini (``--config`` or the usual one), and no ``--no-viewer``,
``--help`` or ``--list-robots``. The settings decide (``app.config``): a page process
started early that the settings do not want is closed, and one they want that was not
started early is started then. This module loads the standard library alone (and
``c2rviz.ini``, which does too).
"""

from __future__ import annotations

import configparser
import socket
import subprocess
import sys
from collections.abc import Sequence

from ..errors import ConfigError
from ..ini import find_ini, read_ini

__all__ = ["Spawned", "close", "early", "spawn"]

Spawned = tuple[subprocess.Popen[bytes], socket.socket]
"""A page process and the program's end of its channel."""

_NOT_NOW = ("--no-viewer", "--help", "-h", "--list-robots")


def spawn() -> Spawned:
    """Start a page process; it and our end of its channel. It loads viser and waits for
    its ``hello`` meanwhile.

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


def early(argv: Sequence[str]) -> Spawned | None:
    """A page process started now if ``argv`` (the program's arguments) or the ini ask for
    one; None otherwise, or if it cannot start (the program tries again and says why)."""
    args = list(argv)
    if any(a in _NOT_NOW for a in args):
        return None
    if "--page-process" not in args and not _ini_wants(args):
        return None
    try:
        return spawn()
    except OSError:
        return None


def _ini_wants(args: list[str]) -> bool:
    """``[options] page_process = on`` in the ini the program will read (a guess: an ini
    that cannot be read says no here; ``app.config`` says why later)."""
    explicit: str | None = None
    for k, arg in enumerate(args):
        if arg == "--config" and k + 1 < len(args):
            explicit = args[k + 1]
        elif arg.startswith("--config="):
            explicit = arg.partition("=")[2]
    try:
        ini = find_ini(explicit)
        if ini is None:
            return False
        return read_ini(ini).get("options", "page_process", fallback="off") == "on"
    except (ConfigError, configparser.Error):
        return False
