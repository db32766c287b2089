"""What the verbs that keep and share do: ``watch``, ``unwatch``, ``trail``, ``record``."""

from __future__ import annotations

import asyncio
from typing import TYPE_CHECKING

from ...observers.recorder import Recorded
from ...observers.recordings import Recordings
from ...observers.trail import TrailKeeper
from ...observers.watch import WatchHub
from ...protocol import replies
from ...protocol.registry import Reply, handler
from ...protocol.verbs.observe import Trail, Unwatch, Watch
from ...protocol.verbs.record import Record

if TYPE_CHECKING:
    from ..session import Session

__all__: list[str] = []


@handler(Watch)
def watch(session: Session, command: Watch) -> str:
    WatchHub.of(session.world).watch(session, command.hz)
    return replies.OK


@handler(Unwatch)
def unwatch(session: Session, command: Unwatch) -> str:
    WatchHub.of(session.world).unwatch(session)
    return replies.OK


@handler(Trail)
def trail(session: Session, command: Trail) -> str:
    keeper = TrailKeeper.of(session.world)
    robot = session.state.name
    if command.action is None:
        on = robot in keeper.trails
        return replies.ok(f"on {len(keeper.trails[robot])}" if on else "off")
    if command.action == "on":
        keeper.start(robot)
    elif command.action == "off":
        keeper.stop(robot)
    else:
        keeper.clear(robot)
    return replies.OK


@handler(Record)
def record(session: Session, command: Record) -> Reply:
    desk = Recordings.of(session.world)
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
