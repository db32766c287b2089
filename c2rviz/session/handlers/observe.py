"""What the verbs that show and keep what happens do: ``watch``, ``unwatch``, ``trail``,
``ghost`` and ``record``: start, stop and ask about this connection's robot's recording (all
``protocol.verbs.observe``)."""

from __future__ import annotations

import asyncio
from typing import TYPE_CHECKING

from ...observers.recorded import Recorded
from ...protocol import replies
from ...protocol.registry import Reply, handler
from ...protocol.verbs.observe import Ghost, Record, Trail, Unwatch, Watch

if TYPE_CHECKING:
    from ..session import Session


@handler(Watch)
def watch(session: Session, command: Watch) -> str:
    session.services.watch.watch(session, command.hz)
    session.listens = True  # only listens from now on, until its next line
    return replies.OK


@handler(Unwatch)
def unwatch(session: Session, command: Unwatch) -> str:
    session.services.watch.unwatch(session)
    return replies.OK


@handler(Trail)
def trail(session: Session, command: Trail) -> str:
    keeper = session.services.trails
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


@handler(Ghost)
def ghost(session: Session, command: Ghost) -> str:
    state = session.state
    if command.shown is None:
        return replies.ok("on" if state.ghost else "off")
    session.world.set_ghost(state.name, command.shown)
    return replies.OK


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
