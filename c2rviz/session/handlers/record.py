"""What ``record`` does: start, stop and ask about this connection's robot's recording."""

from __future__ import annotations

import asyncio
from typing import TYPE_CHECKING

from ...observers.recorded import Recorded
from ...protocol import replies
from ...protocol.registry import Reply, handler
from ...protocol.verbs.record import Record

if TYPE_CHECKING:
    from ..session import Session

__all__ = ["recorded_text"]


@handler(Record)
def record(session: Session, command: Record) -> Reply:
    desk = session.services.recordings
    robot = session.state.name
    if command.stop:
        return _stopped(desk.stop(robot, f"stopped by {session.source}"))
    if command.name is None:
        running = desk.running.get(robot)
        if running is None:
            return replies.ok("not recording")
        return replies.ok(f"recording {running.name} {desk.world.clock.now() - running.t0:.3f}")
    recording = desk.start(command.name, robot, command.overwrite, command.every)
    return replies.ok(f"recording {recording.name} into {desk.folder.resolve()}")


async def _stopped(finished: asyncio.Future[list[Recorded]]) -> str:
    done = await asyncio.shield(finished)  # a client gone meanwhile does not cut it short
    failed = [r for r in done if r.error is not None]
    if failed:
        first = failed[0]
        return replies.error(f"record: {first.name} stopped early ({first.error})")
    return replies.ok(recorded_text(done))


def recorded_text(done: list[Recorded]) -> str:
    """``recorded NAME: N frames, S s (FILES)`` for a finished recording (one ``ROBOT N
    frames`` per robot when it recorded several)."""
    first = done[0]
    bag = first.bag
    name = bag.name if bag is not None else first.name
    if len(done) == 1:
        frames = f"{first.frames} frame{'s' * (first.frames != 1)}"
    else:
        frames = ", ".join(f"{r.name} {r.frames} frames" for r in done)
    files = [p for r in done for p in (r.txt, r.csv, r.html) if p is not None]
    if bag is not None:
        files.append(bag)
    seconds = max(r.duration_s for r in done)
    return f"recorded {name}: {frames}, {seconds:.3f} s ({', '.join(str(p) for p in files)})"
