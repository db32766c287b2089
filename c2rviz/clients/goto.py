"""The REPL's ``goto``: to a joint target by the server's motion, else in small steps.

A server that knows ``motion`` (``motion_of`` reads which mode) plans the
move itself: ``travel`` switches the connection to ``motion on``, sends one
``joints`` line, whose reply comes when the arm arrives, and puts the mode
back; Ctrl-C meanwhile sends ``stop`` on a second connection (the first one's
later lines wait behind the arrival) and reads the arrival's ``error: motion
stopped by ...``. A server from before motion answers ``error: unknown command
'motion'``; there ``step`` sends ``joints`` lines a small step apart at a rate,
as the first c2rviz did.

Values are in the connection's units (``Client.in_degrees``) throughout.
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import dataclass

from ..errors import C2rvizError, JointCountError, JointLimitError, within_limit
from ..protocol.verbs.arm import MOTION_MODES
from .client import Client


def motion_of(reply: str) -> str | None:
    """The connection's motion mode from the reply to a bare ``motion``; None when the
    server has no motion (an older server's ``error: unknown command 'motion' ...``).

    Raises:
        C2rvizError: any other reply.
    """
    if reply.startswith("ok "):
        mode = reply[3:].strip()
        if mode in MOTION_MODES:
            return mode
    elif reply.startswith("error: unknown command"):
        return None
    raise C2rvizError(f"unexpected reply to 'motion': {reply!r}")


def target_problem(client: Client, target: Sequence[float]) -> str | None:
    """Why the server's robot cannot go to ``target`` (count, limits), else None.

    Checked before anything moves, so a target out of reach moves nothing.
    """
    names = client.joint_names()
    if len(target) != len(names):
        return str(JointCountError(len(names), len(target)))
    for i, (value, limit) in enumerate(zip(target, client.limits())):
        if not within_limit(value, limit.lower, limit.upper):
            return str(JointLimitError(names[i], i, value, limit.lower, limit.upper, limit.unit))
    return None


def _joints(values: Sequence[float]) -> str:
    return "joints " + ",".join(map(repr, values))


@dataclass(frozen=True, slots=True)
class Arrival:
    """How a ``travel`` ended.

    Attributes:
        reply: The ``joints`` line's reply: ``ok`` on arrival, else ``error: ...``
            (preempted, stopped), or the refusal of ``motion on``.
        interrupted: Ctrl-C came while the arm travelled, and ``stop`` was sent.
        restored: The reply to putting the motion mode back (empty: nothing to put back).
        seconds: From sending ``joints`` to its reply [s].
    """

    reply: str
    interrupted: bool = False
    restored: str = ""
    seconds: float = 0.0


def travel(client: Client, target: Sequence[float], mode: str) -> Arrival:
    """Go to ``target`` with the server's motion: one ``joints`` line, answered on arrival.

    Args:
        client: A connection with no unread replies, to a server with motion.
        target: The joint values, in the connection's units (checked already).
        mode: The connection's motion mode now (``motion_of``): it is put back.

    Raises:
        ConnectionLost, ServerUnavailable: the server went away.
        KeyboardInterrupt: a second Ctrl-C, while stopping (the connection is closed).
    """
    if mode != "on":
        switched = client.ask("motion on")
        if not switched.startswith("ok"):
            return Arrival(switched)
    start = time.monotonic()
    interrupted = False
    try:
        client.post(_joints(target))
        reply = client.read_reply(interruptible=True)
    except KeyboardInterrupt:
        if not client.pending:  # before the line was out: nothing moves, nothing is due
            client.close()  # (or out but not yet counted: the stream would be out of step)
            raise
        interrupted = True
        try:
            stop_elsewhere(client)
            reply = client.read_reply()  # the arrival, settled by the stop
        except BaseException:  # the reply may never be read: the stream is out of step
            client.close()
            raise
    seconds = time.monotonic() - start
    restored = client.ask(f"motion {mode}") if mode != "on" else ""
    return Arrival(reply, interrupted, restored, seconds)


def stop_elsewhere(client: Client) -> str:
    """Send ``stop`` for ``client``'s robot on a connection of its own; return its reply.

    ``client``'s own later lines wait behind the reply it waits for, so a
    ``stop`` sent there would only run after the arrival. The reply comes when
    the arm is at rest.
    """
    other = Client(client.host, client.port, retry_s=client.retry_s)
    try:
        if client.chosen_robot is not None:  # the REPL drives another robot than the port's
            other.ask(f"robot {client.chosen_robot}")
        return other.ask("stop")
    finally:
        other.close()


@dataclass(frozen=True, slots=True)
class Stepped:
    """How a ``step`` ended.

    Attributes:
        done: Steps answered ``ok``.
        steps: Steps planned.
        reply: The last step's reply (``ok``, or the error that stopped it).
        seconds: From the first step to the last reply [s].
    """

    done: int
    steps: int
    reply: str
    seconds: float


def step(
    client: Client,
    current: Sequence[float],
    target: Sequence[float],
    step_size: float,
    period_s: float,
) -> Stepped:
    """Go from ``current`` to ``target`` in ``joints`` lines at most ``step_size`` apart.

    For a server without motion: each line is shown at once, so the steps at
    ``period_s`` intervals make the move.

    Args:
        client: A connection with no unread replies.
        current, target: Joint values, in the connection's units.
        step_size: Largest change of any joint per line, in the connection's units.
        period_s: Time between lines [s].
    """
    distance = max(abs(t - c) for t, c in zip(target, current))
    steps = max(1, math.ceil(distance / step_size - 1e-9))
    start = time.monotonic()
    reply = "ok"
    for k in range(1, steps + 1):
        if k > 1:
            time.sleep(max(0.0, start + (k - 1) * period_s - time.monotonic()))
        values = (
            target if k == steps else [c + (t - c) * k / steps for t, c in zip(target, current)]
        )
        reply = client.ask(_joints(values))
        if not reply.startswith("ok"):
            return Stepped(k - 1, steps, reply, time.monotonic() - start)
    return Stepped(steps, steps, reply, time.monotonic() - start)
