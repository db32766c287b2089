"""What the scene's verbs do (``protocol.verbs.scene``): ``watch``, ``unwatch``, ``trail``,
``ghost`` and ``record`` (start, stop and ask about this connection's robot's
recording); the workcell's objects, collisions now and this connection's guard
(``object``, ``objects``, ``collisions``, ``guard``); and ``plan``: a path around the
obstacles to joint values or a tool pose, and its settings.

The search runs on the worker's plan lane (``guarded.checked_move`` with
``plan="always"``: the direct edge first, then RRT-Connect and shortening; ``stop``,
the client closing or a newer move cancel it), the
path is timed within the joints' limits at the connection's speed and played on
the world's clock (``motion on``: the reply waits for the arrival; ``follow``: it
comes as the arm leaves; ``off``: the arm is shown at the goal at once), and the
guard's watch re-checks it while it runs, whatever the connection's guard.
"""

from __future__ import annotations

import asyncio
from typing import TYPE_CHECKING

from ...errors import BadArguments, JointCountError
from ...ik.chain import PointTarget, Target
from ...observers.recorded import Recorded
from ...planning import MAX_TIMEOUT_S, goal_candidates, time_path
from ...planning.errors import checked_setting
from ...planning.validity import RANGES
from ...protocol import replies
from ...protocol.registry import Reply, handler, usage
from ...protocol.verbs.scene import (
    Collisions,
    Ghost,
    Guard,
    ObjectEdit,
    Objects,
    Plan,
    Record,
    Trail,
    Unwatch,
    Watch,
)
from ..guarded import checked_move, play_checked

if TYPE_CHECKING:
    from ...collision.model import CollisionModel
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


@handler(ObjectEdit)
def object_edit(session: Session, command: ObjectEdit) -> str:
    name, shape = command.name, command.shape

    def edit(model: CollisionModel) -> None:
        if shape != "remove":
            model.set_object(name, shape, command.size, session.pose_se3(command.pose))
        elif name == "all":
            model.remove_all()
        else:
            model.remove_object(name)

    session.world.edit_objects(session.state.name, edit)
    return replies.OK


@handler(Objects)
def objects(session: Session, command: Objects) -> str:
    names = session.world.collision_model(session.state.name).objects()
    return replies.ok(",".join(names) if names else "none")


@handler(Collisions)
def collisions(session: Session, command: Collisions) -> str:
    return replies.ok(replies.pairs(session.world.contacts.now(session.state.name)))


@handler(Guard)
def guard(session: Session, command: Guard) -> str:
    if command.on is None:
        if not session.guard:
            return replies.ok("off")
        return replies.ok("plan" if session.plan_around else "on")
    if command.on:
        for name in session.world.robots:  # built now, not mid-command (a cell counts all)
            session.world.collision_model(name)
    session.guard = command.on
    session.plan_around = command.plan
    return replies.OK


MIN_TIMEOUT_S = 0.001  # [s] shortest search a connection may set


@handler(Plan)
def plan(session: Session, command: Plan) -> Reply:
    what, values = command.what, command.values
    if what == "show":  # the path of the last `plan`, or of the last `guard plan` move
        if session.last_plan is None:
            return replies.ok("none")
        return replies.ok(";".join(replies.numbers(session.from_si(q)) for q in session.last_plan))
    if what == "timeout":
        if not values:
            return replies.ok(replies.numbers([session.plan_timeout_s]))
        session.plan_timeout_s = checked_setting(
            "plan timeout", values[0], MIN_TIMEOUT_S, MAX_TIMEOUT_S, "s"
        )
        return replies.OK
    if what == "resolution":
        step_rad, tool_m = session.steps
        if not values:
            shown = [step_rad / session.angle_scale, tool_m if tool_m is not None else 0.0]
            return replies.ok(replies.numbers(shown))
        _check_steps(session, *values)
        session.set_steps(values[0] * session.angle_scale, values[1])
        return replies.OK
    if what == "joints":
        n = session.n
        if len(values) != n:
            raise JointCountError(n, len(values))
        return _plan_to(session, [session.to_si(range(n), values)])
    target: Target = PointTarget.at(values) if len(values) == 3 else session.pose_se3(values)
    return _plan_pose(session, target)


async def _plan_pose(session: Session, target: Target) -> str:
    state, worker = session.state, session.services.worker
    solver, near, tool = worker.ik_solver(state), session.now(), state.tool
    goals = await worker.run(lambda: goal_candidates(solver, target, near, tool), owner=session)
    return await _plan_to(session, goals)


async def _plan_to(session: Session, goals: list) -> str:
    checked, _ = await checked_move(session, goals, plan="always")
    session.last_plan = checked.waypoints
    world, state = session.world, session.state
    length = checked.planned.length_rad if checked.planned is not None else 0.0
    count = len(checked.waypoints)
    if session.motion == "off":
        limits = world.motion_limits(state.name)
        timed = time_path(checked.waypoints, limits, 0.0, session.speed / 100.0)
        world.set_q(checked.goal, state.name, session.source)
        return _summary(count, length, timed.duration)
    play, arrival = play_checked(session, checked)
    reply = _summary(count, length, play.duration)
    if arrival is not None:
        await arrival
    return reply


def _check_steps(session: Session, angle: float, tool_m: float) -> None:
    """Refuse steps outside the ranges, in the connection's units."""
    scale, unit = session.angle_scale, "deg" if session.degrees else "rad"
    low, high = RANGES["max_step_rad"]
    if not low <= angle * scale <= high:
        problem = (
            f"a joint step of {angle:g} {unit} is outside {low / scale:.4g}..{high / scale:.4g}"
        )
        raise BadArguments("plan", f"{problem} {unit}", usage("plan"))
    low, high = RANGES["max_tool_step_m"]
    if not low <= tool_m <= high:
        problem = f"a tool step of {tool_m:g} m is outside {low:g}..{high:g} m"
        raise BadArguments("plan", problem, usage("plan"))


def _summary(count: int, length_rad: float, duration_s: float) -> str:
    return replies.ok(f"{count} waypoints {length_rad:.3f} rad {duration_s:.3f} s")
