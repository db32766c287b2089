"""What a CRCL ``Controller`` keeps of each command: its report, its job, the lanes.

A ``Report`` is a command as its statuses tell it (CommandID, name, state, why). A
``Job`` is a command that takes time, running in a lane (``ARM``, ``GRIPPER``,
``DWELL``: each runs one command of a connection at a time).
"""

from __future__ import annotations

import asyncio
import logging
from collections.abc import Awaitable, Callable
from dataclasses import dataclass
from typing import Any, Final

from ...errors import C2rvizError, MotionInterrupted
from ...protocol import replies
from ...protocol.registry import Reply
from ...session.notes import Said
from ...session.session import Session
from .commands import GetStatus, InitCanon
from .documents import CommandInstance, parse_instance
from .errors import CrclError
from .reports import ConnectionSettings, StatusParts
from .scalars import xml_safe_text
from .status import CommandStatus, CrclStatus

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


log = logging.getLogger("c2rviz.crcl")

MAX_DESCRIPTION: Final = 400
"""Longest StateDescription of a full status [characters]; a longer one is cut."""
PUSHED_DESCRIPTION: Final = 240
"""Longest StateDescription of a pushed status, and of a ``ProgramFile`` echoed
[characters]: a compact status stays under 1 KiB, one per ``recv(1024)``."""


JobBody = Callable[["Controller", Job], Awaitable[None]]
"""``body(controller, job)``: what a job does (``motions``)."""
Action = Callable[["Controller", Report, Any], "str | None"]
"""``action(controller, report, command)``: do the command (see ``actions``); return the
``StateDescription`` of its CRCL_Done (None: none), or raise to refuse it."""


def registrar(table: dict[type, Action]) -> Callable[..., Callable[[Action], Action]]:
    """A decorator that enters an action in ``table`` for the command types it names."""

    def named(*types: type) -> Callable[[Action], Action]:
        def register(action: Action) -> Action:
            for kind in types:
                table[kind] = action
            return action

        return register

    return named


class Controller:
    """See the module docstring.

    Args:
        session: The connection's session (its motion is set ``on``, its guard on).
        send: Writes one status document to the client.
        actions: What each command type does (``actions.ACTIONS``).
    """

    def __init__(
        self,
        session: Session,
        send: Callable[[bytes], None],
        actions: dict[type, Action],
    ) -> None:
        self.session = session
        session.set_motion("on")  # a command is Working until its motion arrives
        session.set_guard(True)  # a colliding target or path is refused, never driven into
        self.settings = ConnectionSettings()
        self.parts = StatusParts(session, self.settings)
        self.canon = False
        self.ended = False
        """An EndCanon came (so a command now is "after EndCanon")."""
        self.latest = Report(0, "no command yet", READY)
        self.lanes: dict[str, Job] = {}
        self._send = session.world.faults.late_sends(lambda: session.state.name, send)
        """Statuses go out through it: late by a latency fault, in order (docs/faults.md)."""
        self._actions = actions
        self._status_id = 0
        self._closed = False

    # documents in

    def receive(self, doc: bytes | CommandInstance) -> None:
        """Run one command document (its motion, if any, goes on in a task); a large
        one comes parsed already (``parse_instance``, off the event loop)."""
        if isinstance(doc, CommandInstance):
            instance = doc
        else:
            try:
                instance = parse_instance(doc)
            except CrclError as error:
                self.refuse_document(error)
                return
        command = instance.command
        if isinstance(command, GetStatus):
            self._send_status(self.latest, full=True)
            return
        report = Report(
            command.command_id,
            f"{command.XSI_TYPE} (CommandID {command.command_id})",
            program_file=instance.program_file,
            program_index=instance.program_index,
            program_length=instance.program_length,
            said=self.session.said(f"{command.XSI_TYPE} (CommandID {command.command_id})"),
        )
        self.latest = report
        try:
            if command.guards:
                raise Refused("guards need sensors, and c2rviz simulates none")
            if not self.canon and not isinstance(command, InitCanon):
                state = "after EndCanon" if self.ended else "before InitCanon"
                raise Refused(f"{state}: send InitCanon first")
            description = self._actions[command.__class__](self, report, command)
        except C2rvizError as error:
            self.settings.revision += 1  # an action may have set something before it refused
            self.finish(report, ERROR, str(error), error=error)
            return
        self.settings.revision += 1
        if report.said is not None:
            report.said.accept()
        if report.state == WORKING and not self._runs(report):
            self.finish(report, DONE, description)

    def refuse_document(self, error: CrclError) -> None:
        """A document (or bytes) refused before it was a command: report it as an error."""
        command_id = error.command_id if error.command_id is not None else 0
        said = self.session.said(f"refused: {error.description}")
        report = Report(command_id, error.command_type or "document", said=said)
        self.latest = report
        self.finish(report, ERROR, error.description, named=True, error=error)

    # lanes and jobs

    def start(self, lane: str, report: Report, body: JobBody, takes: tuple[str, ...] = ()) -> None:
        """Run ``body`` as the command of ``lane`` (and of ``takes``: lanes it stops too),
        taking over the command Working there."""
        job = Job(report, lane)
        old = self.lanes.get(lane)
        if old is not None:
            under_way = old if old.moving else old.under_way
            job.under_way = under_way if under_way is not None and not under_way.over else None
        for name in (lane, *takes):
            self.take_over(name, report)
        self.lanes[lane] = job
        self._push(report)
        job.task = asyncio.get_running_loop().create_task(self._run(job, body))

    def take_over(self, lane: str, successor: Report) -> None:
        """``successor`` takes ``lane`` over: its job is reported now if it has not moved
        (and given up), else when the successor's motion interrupts it."""
        old = self.lanes.get(lane)
        if old is None or old.over:
            return
        old.successor = successor
        if lane == DWELL and old.task is not None:  # a pause has nothing to finish
            old.task.cancel()
            self.finish(old.report, DONE, f"taken over by {successor.what}")
        # A job that has not moved yet ends as its planning does: refused (CRCL_Error),
        # or at ``moving`` (CRCL_Done, taken over before it moved).

    @staticmethod
    async def moving(job: Job, start: Callable[[], Reply]) -> None:
        """Start ``job``'s motion (``start()``: the session's reply, ``ok`` on arrival) and
        wait for it; none if the job was taken over meanwhile.

        Raises:
            TakenOver: taken over before its motion began (nothing moved).
        """
        if job.successor is not None and not job.moving:
            raise TakenOver()
        reply = start()
        job.moving = True
        job.under_way = None
        if not isinstance(reply, str):
            await reply

    async def _run(self, job: Job, body: JobBody) -> None:
        report = job.report
        try:
            await body(self, job)
        except TakenOver:
            assert job.successor is not None
            self.finish(report, DONE, f"taken over by {job.successor.what} before it moved")
        except MotionInterrupted as interrupted:
            own = interrupted.why.endswith(f"by {self.session.source}")
            if job.successor is not None and own:
                self.finish(report, DONE, f"stopped short: taken over by {job.successor.what}")
            else:
                why = f"stopped short: {interrupted.why}"
                self.finish(report, ERROR, why, error=interrupted)
        except C2rvizError as error:
            self.finish(report, ERROR, str(error), error=error)
        except asyncio.CancelledError:
            raise
        except Exception:  # a bug costs this command, never the server
            log.exception("internal error running %s", report.what)
            self.finish(report, ERROR, "internal error (see the server log)")
        else:
            self.finish(report, DONE)

    def _runs(self, report: Report) -> bool:
        return any(job.report is report for job in self.lanes.values())

    # statuses out

    def finish(
        self,
        report: Report,
        state: str,
        why: str | None = None,
        named: bool = False,
        error: C2rvizError | None = None,
    ) -> None:
        """``report``'s command ends in ``state``: say so (once), with ``why`` after the
        command's name (``named``: ``why`` names it already); the world hears of it, an
        ``ERROR`` as a refusal (with ``error``: what refused it)."""
        if report.state != WORKING and report.state != READY:
            return
        report.state = state
        report.description = why if why is None or named else f"{report.what}: {why}"
        said = report.said
        if said is not None:
            if state == ERROR:
                said.refuse(error if error is not None else Refused(why or "refused"))
            else:
                said.accept()
                said.reply(replies.OK if why is None else replies.ok(why))
        self._push(report)

    def _push(self, report: Report) -> None:
        self._send_status(report, full=False)

    def _send_status(self, report: Report, full: bool) -> None:
        if self._closed:
            return
        try:
            self._send.send(self.parts.write(self.status(report, full)))
        except C2rvizError:  # a value a status cannot carry (a bug): say it in the log
            log.exception("cannot write a status for %s", report.what)

    def status(self, report: Report, full: bool) -> CrclStatus:
        """A status about ``report``: full (every part the reports ask for) or compact."""
        self._status_id += 1
        state, description = report.state, report.description
        faults = self.session.world.faults
        stop = faults.of(self.session.state.name).refusal(faults.origin)
        if stop is not None:  # a stop (fault estop, protective) holds the arm: every status says so
            state, description = ERROR, str(stop)
        if description is not None:
            description = xml_safe_text(description)[
                : MAX_DESCRIPTION if full else PUSHED_DESCRIPTION
            ]
        program_file = report.program_file
        command = CommandStatus(
            command_id=report.command_id,
            status_id=self._status_id,
            state=state,
            description=description,
            program_file=program_file[:PUSHED_DESCRIPTION] if program_file else program_file,
            program_index=report.program_index,
            program_length=report.program_length,
        )
        parts, asked = self.parts, self.settings.status_report
        if not full:
            return CrclStatus(
                command_status=command,
                joint_statuses=parts.joints(configured_only=True),
                pose_status=parts.pose(),
            )
        return CrclStatus(
            command_status=command,
            joint_statuses=parts.joints() if asked is None or asked.report_joint_statuses else None,
            pose_status=parts.pose() if asked is None or asked.report_pose_status else None,
            gripper_status=parts.gripper()
            if asked is None or asked.report_gripper_status
            else None,
            settings_status=parts.settings_status()
            if asked is None or asked.report_settings_status
            else None,
        )

    def close(self) -> None:
        """The connection ended: nothing more is sent; commands not yet moving are dropped
        (a motion under way goes on to its target, as a text client's does)."""
        self._closed = True
        self._send.close()
        for job in self.lanes.values():
            if job.task is not None and not job.task.done():
                job.task.cancel()
