"""What ``record`` does: start, stop and ask about the recording."""

from __future__ import annotations

import asyncio
from typing import TYPE_CHECKING

from ...observers.recorder import Recorded
from ...protocol import replies
from ...protocol.registry import Reply, handler
from ...protocol.verbs.record import Record

if TYPE_CHECKING:
    from ..session import Session

__all__: list[str] = []


@handler(Record)
def record(session: Session, command: Record) -> Reply:
    desk = session.services.recordings
    if command.stop:
        return _stopped(desk.stop(f"stopped by {session.source}"))
    if command.name is None:
        current = desk.current
        if current is None:
            return replies.ok("not recording")
        return replies.ok(f"recording {current.name} {current.seconds:.3f}")
    recorder = desk.start(command.name, session.state.name, command.overwrite)
    return replies.ok(f"recording {recorder.name} into {desk.folder.resolve()}")


async def _stopped(finished: asyncio.Future[Recorded]) -> str:
    recorded = await finished
    if recorded.error is not None:
        return replies.error(f"record: {recorded.name} stopped early ({recorded.error})")
    return replies.ok(
        f"recorded {recorded.name}: {recorded.frames} frame{'s' * (recorded.frames != 1)}, "
        f"{recorded.duration_s:.3f} s "
        f"({', '.join(str(p) for p in (recorded.txt, recorded.csv, recorded.html) if p)})"
    )
