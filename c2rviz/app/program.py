"""The running program: the world, its services, a command server per robot, the viewer,
until quit, SIGINT or SIGTERM (``serve``; ``members`` says which robots).
"""

from __future__ import annotations

import asyncio
import errno
import gc
import ipaddress
import logging
import secrets
import signal
import sys
from collections.abc import Awaitable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ..collision.geometry import read_srdf
from ..errors import C2rvizError, ConfigError
from ..observers.recorded import Recorded
from ..protocol.verbs.scene import Record
from ..session.services import Services
from ..transports.tcp_server import CommandServer
from ..world.clock import Clock
from ..world.observer import NullScene, Scene
from ..world.state import RobotState
from ..world.virtual_clock import parse_clock
from ..world.world import World
from .config import Settings, replaced_bundled
from .doors import close_doors, open_doors
from .ini_world import ini_cameras, place_cameras
from .members import Member, furnish

log = logging.getLogger("c2rviz")


def _is_loopback(host: str) -> bool:
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


_STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)
_CLOCK_NOTES = {
    False: "motion, sleep, watch stamps and recordings run on it",
    True: "time jumps ahead whenever every client waits on it: sleep, wait, an arrival",
}


def write_page(recorded: Recorded, state: RobotState) -> Path:
    """NAME.html of a finished recording (viser is loaded only now, in the recording's
    thread, so a program without a viewer never loads it unless it records)."""
    from ..view.record_page import write_html

    return write_html(recorded, state)


def _open_scene(
    settings: Settings,
    services: Services,
    title: str | None,
    page_process: bool = False,
    spawned: Any = None,
) -> Scene:
    if not settings.viewer:
        return NullScene()
    token = settings.viewer_token
    if token is None and not _is_loopback(settings.viewer_host):
        token = secrets.token_urlsafe(16)
    if page_process:  # the page in a process of its own: viser is never loaded here
        from ..view.page_link import PageLink
        from ..view.page_snapshot import RECENT_COMMANDS, PageConfig

        config = PageConfig(
            settings.viewer_host,
            settings.viewer_port,
            settings.hz,
            settings.viewer_origins,
            token,
            settings.max_viewers,
            title,
            settings.session,
            settings.trail_points,
            logging.getLogger().getEffectiveLevel(),
            RECENT_COMMANDS,
            settings.viewer_lighting,
        )
        return PageLink(services, config, spawned)
    from ..view.door_rules import DoorPolicy
    from ..view.viser_scene import ViserScene  # viser is heavy: import only when it is used

    policy = DoorPolicy(settings.viewer_origins, token, settings.max_viewers)
    return ViserScene(
        services,
        settings.viewer_host,
        settings.viewer_port,
        settings.hz,
        policy=policy,
        title=title,
        port_named=settings.viewer_port_named,
        lighting=settings.viewer_lighting,
    )


def _cannot_listen(host: str, port: int, exc: OSError, cell: str | None) -> str:
    """Why the command server cannot start, in one sentence."""
    if exc.errno == errno.EADDRINUSE:
        how = (
            f"choose the cell's first port with --port (the others follow; 0 picks free ones) "
            f"or fix each member's port in [cell:{cell}]'s members"
            if cell is not None
            else "choose another with --port (0 picks a free one)"
        )
        return (
            f"cannot listen for commands on {host}:{port}: the port is in use "
            f"(another c2rviz?); {how}"
        )
    return f"cannot listen for commands on {host}:{port}: {exc.strerror or exc}"


async def serve(
    settings: Settings,
    members: Sequence[Member],
    cell: str | None = None,
    clock: Clock | None = None,
    page_process: bool = False,
    spawned: Any = None,
) -> int:
    """Run the viewer and a command server per robot until ``quit``, SIGINT or SIGTERM.

    ``page_process``: the page runs in a process of its own (``--page-process``,
    docs/page.md), started here unless ``spawned`` (``page_start.fork``), stopped last.

    ``members`` are the robots, each by the name the user chose (``--robot kuka_lwr``,
    or a cell's member name), which the banner and ``names`` say. Every command port
    is bound first: when one is taken the program says so and stops before the
    viewer starts (so no word about the viewer's port either).
    """
    loop = asyncio.get_running_loop()
    stop = asyncio.Event()
    if spawned is None and page_process and settings.viewer:
        spawned = _spawn_page()
    srdf = read_srdf(settings.srdf) if settings.srdf is not None else None
    if clock is None:
        clock = parse_clock(settings.clock)
    world = World(
        {m.name: m.robot for m in members},
        clock=clock,
        hz=settings.hz,
        origins={m.name: m.origin for m in members},
        limits={m.name: m.limits for m in members},
        disabled_pairs={members[0].name: srdf} if srdf is not None else None,
        max_objects=settings.max_objects,
    )
    services = Services(
        world,
        limits=settings.limits,
        defaults=settings.session,
        rng=np.random.default_rng(settings.session.plan_seed),  # a seed repeats rand too
        record_dir=settings.record_dir,
        trail_points=settings.trail_points,
        exporters=(write_page,),
    )
    try:
        for member in members:
            furnish(world, member)
        place_cameras(world, services.rng, ini_cameras(settings.ini))
        _record_from_start(services, settings)
    except C2rvizError as exc:
        print(f"c2rviz: {exc}", file=sys.stderr)
        return 2
    servers: list[CommandServer] = []
    for member in members:
        server = CommandServer(services, on_quit=stop.set, robot=member.name)
        try:
            host, port = await server.start(settings.host, member.port)
        except OSError as exc:
            print(
                f"c2rviz: {_cannot_listen(settings.host, member.port, exc, cell)}", file=sys.stderr
            )
            for started in servers:
                await started.stop()
            return 2
        world.state(member.name).port = port
        servers.append(server)
    try:
        doors = await open_doors(settings, services, members, stop.set)
    except C2rvizError as exc:
        print(f"c2rviz: {exc}", file=sys.stderr)
        for server in servers:
            await server.stop()
        return 2
    scene: Scene = NullScene()
    try:
        scene = _open_scene(settings, services, cell, page_process, spawned)
        world.add_observers([scene])  # no client is served before this: nothing awaited since
        scene.start(loop)
        await _page_opened(scene)
    except (OSError, C2rvizError) as exc:
        problem = exc.strerror or exc if isinstance(exc, OSError) else exc
        print(
            f"c2rviz: cannot serve the viewer on {settings.viewer_host}:{settings.viewer_port}: "
            f"{problem}",
            file=sys.stderr,
        )
        await close_doors(doors)
        for server in servers:
            await server.stop()
        scene.stop()
        return 2
    for server in servers:
        server.viewer_url = scene.url
    for sig in _STOP_SIGNALS:
        loop.add_signal_handler(sig, stop.set)
    for name in replaced_bundled(settings.robots):
        print(
            f"c2rviz: note: [{name}] of {settings.robots[name].ini} replaces the bundled robot "
            "of that name",
            flush=True,
        )
    if cell is not None:
        print(f"c2rviz: cell {cell}: {', '.join(m.name for m in members)}", flush=True)
    for member in members:
        _banner(member, settings.host, world.state(member.name).port, cell is not None)
    for entry in doors:
        print(f"c2rviz: {entry.banner}", flush=True)
    if clock.describe() != "real":
        print(f"c2rviz: clock {clock.describe()} ({_CLOCK_NOTES[clock.virtual]})", flush=True)
    if scene.url:
        print(f"c2rviz: viewer at {scene.url}", flush=True)
    if not _is_loopback(settings.host):
        print(
            f"c2rviz: warning: the command server listens on {settings.host}: anyone who can "
            "reach it can move the robot and stop the program",
            file=sys.stderr,
            flush=True,
        )
    if settings.viewer and not _is_loopback(settings.viewer_host):
        made = " (generated for this run; --viewer-token sets one)"
        print(
            f"c2rviz: warning: the viewer listens on {settings.viewer_host}: anyone who can "
            "reach it and has its URL with the token can move the robot"
            f"{made if settings.viewer_token is None else ''}",
            file=sys.stderr,
            flush=True,
        )
    for entry in doors:
        if entry.warning is not None:
            print(f"c2rviz: warning: {entry.warning}", file=sys.stderr, flush=True)
    # What start-up built (the models, the meshes, the modules) lives as long as the
    # program: moved out of the collector's sight, a full collection that a client's big
    # input sets off walks only what came since (it walked it all: tens of ms a time).
    gc.freeze()
    try:
        await stop.wait()
    finally:
        # The recordings stop first and are awaited whatever closing the doors does (a
        # signal meanwhile changes nothing: the handlers stay until they are complete);
        # each step runs whatever the one before it met.
        finishing = services.recordings.close("the program stopped")  # stopped here, now
        try:
            await _step("closing the doors", close_doors(doors))
            for server in servers:
                await _step("stopping a command server", server.stop())
            services.close()
        finally:
            _recorded(await finishing)
            for sig in _STOP_SIGNALS:
                loop.remove_signal_handler(sig)
            scene.stop()
    print("c2rviz: stopped", flush=True)
    return 0


def _spawn_page() -> Any:
    """The page process, started first: it loads viser while we set up (it then waits for
    the world); None if it cannot be started now (the scene tries again, and says why)."""
    from ..view.page_start import spawn

    try:
        return spawn()
    except OSError:
        return None


async def _page_opened(scene: Scene) -> None:
    """Wait until a page in a process of its own serves the page (its URL is then known)."""
    opened = getattr(scene, "opened", None)
    if opened is not None:
        await opened()


async def _step(what: str, step: Awaitable[None]) -> None:
    """Await one step of the shutdown; a failure is logged, and the shutdown goes on."""
    try:
        await step
    except Exception:
        log.exception("while %s", what)


def _banner(member: Member, host: str, port: int | None, in_cell: bool) -> None:
    robot, name = member.robot, member.name
    model = "" if name == robot.name else f" (model {robot.name})"
    who = f"{name}: " if in_cell else ""
    print(
        f"c2rviz: {name}{model}, chain {robot.base} -> {robot.eelink}, "
        f"joints 0..{robot.n - 1}: {' '.join(robot.joint_names)}",
        flush=True,
    )
    print(
        f"c2rviz: {who}commands on {host}:{port} (try: c2rviz-cli --port {port}, then 'help')",
        flush=True,
    )


def _record_from_start(services: Services, settings: Settings) -> None:
    """``--record NAME`` begins now (every robot of a cell); say so, and where."""
    if settings.record is None:
        return
    if Record.parse("record", [settings.record]).stop:  # the verb's rules for a name
        raise ConfigError("--record needs a name; 'stop' is not one")
    desk = services.recordings
    world = services.world
    recording = desk.start(
        settings.record, world.default, settings.record_overwrite, len(world.robots) > 1
    )
    files = ", ".join(
        f"{recorder.name}{suffix}"
        for recorder in recording.recorders.values()
        for suffix in (".txt", ".csv", ".html")
    )
    print(
        f"c2rviz: recording {recording.name} into {desk.folder.resolve()} until exit: "
        f"{files} and the bag {recording.name}/",
        flush=True,
    )


def _recorded(finished: Sequence[Recorded]) -> None:
    """Say what each recording finished at exit holds."""
    for done in finished:
        if done.error is None and done.txt is not None:
            where = f"{done.txt} (and {done.csv.name}"
            where += "".join(f", {p.name}" for p in (done.html,) if p is not None)
            where += f", {done.bag.name}/)" if done.bag is not None else ")"
        else:
            where = f"{done.csv} ({done.error})"
        print(f"c2rviz: recorded {done.name}: {done.frames} frames, {where}", flush=True)
