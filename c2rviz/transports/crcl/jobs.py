"""What a CRCL ``Controller`` keeps of each command: its report, its job, the lanes.

A ``Report`` is a command as its statuses tell it (CommandID, name, state, why). A
``Job`` is a command that takes time, running in a lane (``ARM``, ``GRIPPER``,
``DWELL``: each runs one command of a connection at a time).
"""

from __future__ import annotations

import asyncio
from dataclasses import dataclass

from ...errors import C2rvizError
from ...session.notes import Said

__all__ = [
    "ARM",
    "DONE",
    "DWELL",
    "ERROR",
    "GRIPPER",
    "READY",
    "WORKING",
    "Job",
    "Refused",
    "Report",
    "TakenOver",
]

DONE, ERROR, WORKING, READY = "CRCL_Done", "CRCL_Error", "CRCL_Working", "CRCL_Ready"
ARM, GRIPPER, DWELL = "arm", "gripper", "dwell"
"""The lanes: each runs one command at a time; a new one takes over."""


class Refused(C2rvizError):
    """A command c2rviz will not carry out; the message says why."""


class TakenOver(Exception):
    """A job taken over before its motion began: it starts none (``Controller.moving``)."""


@dataclass(eq=False)
class Report:
    """A command as its statuses report it."""

    command_id: int
    what: str
    """``MoveToType (CommandID 3)``, as the codec's errors name a command."""
    state: str = WORKING
    description: str | None = None
    program_file: str | None = None
    program_index: int | None = None
    program_length: int | None = None
    said: Said | None = None
    """How the world is told of it (``Session.said``), once it is a command."""


@dataclass(eq=False)
class Job:
    """A command running in a lane: its task, whether its motion began, who took over."""

    report: Report
    lane: str
    task: asyncio.Task[None] | None = None
    moving: bool = False
    successor: Report | None = None
    under_way: Job | None = None
    """This connection's job of the lane still moving when this one started (its motion
    is this one's to brake or blend from), until this one moves."""

    @property
    def over(self) -> bool:
        return self.report.state != WORKING
