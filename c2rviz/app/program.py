"""The running program: the world, a command server per robot, the viewer, until quit.

``members`` turns the settings (one robot, or a ``--cell``) into the robots to
serve, with what the ini gives each (``furnish``); ``serve`` runs them.
"""

from __future__ import annotations

import argparse
import asyncio
import errno
import ipaddress
import secrets
import signal
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin

from ..collision.geometry import read_srdf
from ..collision.model import CollisionModel
from ..errors import C2rvizError, ConfigError
from ..motion.planner import MotionLimits
from ..observers.recordings import Recordings
from ..observers.trail import TrailKeeper
from ..protocol.verbs.record import Record
from ..robot.model import Robot
from ..transports.tcp_text import CommandServer
from ..world.effects import NullScene, Scene
from ..world.world import World
from .cell import load_cell
from .config import Settings
from .robot_options import IniObject, ini_objects, limits_from, tool_from

__all__ = ["MOTION_FLAGS", "Member", "members", "serve"]


def _is_loopback(host: str) -> bool:
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


_STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)


def _open_scene(settings: Settings, world: World, title: str | None) -> Scene:
    if not settings.viewer:
        return NullScene()
    from ..view.policy import DoorPolicy
    from ..view.viser_scene import ViserScene  # viser is heavy: import only when it is used

    token = settings.viewer_token
    if token is None and not _is_loopback(settings.viewer_host):
        token = secrets.token_urlsafe(16)
    policy = DoorPolicy(settings.viewer_origins, token, settings.max_viewers)
    return ViserScene(
        world, settings.viewer_host, settings.viewer_port, settings.hz, policy=policy, title=title
    )


def _cannot_listen(host: str, port: int, exc: OSError) -> str:
    """Why the command server cannot start, in one sentence."""
    if exc.errno == errno.EADDRINUSE:
        return (
            f"cannot listen for commands on {host}:{port}: the port is in use "
            "(another c2rviz?); choose another with --port (0 picks a free one)"
        )
    return f"cannot listen for commands on {host}:{port}: {exc.strerror or exc}"


@dataclass(frozen=True)
class Member:
    """One robot the program serves: its name, model, place in the world and port, and
    what the ini gives it (``furnish``)."""

    name: str
    robot: Robot
    origin: pin.SE3
    port: int
    limits: MotionLimits
    tool: pin.SE3 | None = None
    objects: tuple[IniObject, ...] = ()


async def serve(settings: Settings, members: Sequence[Member], cell: str | None = None) -> int:
    """Run the viewer and a command server per robot until ``quit``, SIGINT or SIGTERM.

    ``members`` are the robots, each by the name the user chose (``--robot kuka_lwr``,
    or a cell's member name), which the banner and ``names`` say. Every command port
    is bound first: when one is taken the program says so and stops before the
    viewer starts (so no word about the viewer's port either).
    """
    loop = asyncio.get_running_loop()
    stop = asyncio.Event()
    srdf = read_srdf(settings.srdf) if settings.srdf is not None else None
    world = World(
        {m.name: m.robot for m in members},
        hz=settings.hz,
        defaults=settings.session,
        origins={m.name: m.origin for m in members},
        limits={m.name: m.limits for m in members},
        disabled_pairs={members[0].name: srdf} if srdf is not None else None,
        max_objects=settings.max_objects,
    )
    try:
        for member in members:
            _furnish(world, member)
        _keep(world, settings)
    except C2rvizError as exc:
        print(f"c2rviz: {exc}", file=sys.stderr)
        return 2
    servers: list[CommandServer] = []
    for member in members:
        server = CommandServer(world, settings.limits, on_quit=stop.set, robot=member.name)
        try:
            host, port = await server.start(settings.host, member.port)
        except OSError as exc:
            print(f"c2rviz: {_cannot_listen(settings.host, member.port, exc)}", file=sys.stderr)
            for started in servers:
                await started.stop()
            return 2
        world.state(member.name).port = port
        servers.append(server)
    try:
        scene = _open_scene(settings, world, cell)
    except (OSError, C2rvizError) as exc:
        problem = exc.strerror or exc if isinstance(exc, OSError) else exc
        print(
            f"c2rviz: cannot serve the viewer on {settings.viewer_host}:{settings.viewer_port}: "
            f"{problem}",
            file=sys.stderr,
        )
        for server in servers:
            await server.stop()
        return 2
    world.add_observers([scene])  # no client is served before this: nothing awaited since
    for server in servers:
        server.viewer_url = scene.url
    scene.start(world, loop)
    for sig in _STOP_SIGNALS:
        loop.add_signal_handler(sig, stop.set)
    if cell is not None:
        print(f"c2rviz: cell {cell}: {', '.join(m.name for m in members)}", flush=True)
    for member in members:
        _banner(member, settings.host, world.state(member.name).port, cell is not None)
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
    try:
        await stop.wait()
    finally:
        for sig in _STOP_SIGNALS:
            loop.remove_signal_handler(sig)
        for server in servers:
            await server.stop()
        world.close()
        await _stop_recording(world)
        scene.stop()
    print("c2rviz: stopped", flush=True)
    return 0


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


MOTION_FLAGS = ("max_velocity", "max_acceleration", "max_jerk")


def _furnish(world: World, member: Member) -> None:
    """Give a robot of the world its ini tool and objects (a bad object raises)."""
    if member.tool is not None:
        world.set_tool(member.name, member.tool)
    for name, shape, size, placement, rgba, mesh in member.objects:

        def add(model: CollisionModel) -> None:
            model.set_object(name, shape, size, placement, rgba, mesh)  # noqa: B023 (run now)

        world.edit_objects(member.name, add)


def _member(
    name: str,
    robot: Robot,
    origin: pin.SE3,
    port: int,
    section: str,
    extras: tuple[tuple[str, str], ...],
    ini: Path | None,
    first: bool,
    flags: dict[str, str],
) -> Member:
    given = {**dict(extras), **flags}
    objects = tuple(ini_objects(ini, name, first)) if ini is not None else ()
    return Member(
        name,
        robot,
        origin,
        port,
        limits_from(section, given, robot),
        tool_from(section, given),
        objects,
    )


def members(settings: Settings, args: argparse.Namespace) -> tuple[list[Member], str | None]:
    """The robots to serve: the cell's (``--cell``), or the one robot of the settings."""
    flags = {k: getattr(args, k) for k in MOTION_FLAGS if getattr(args, k) is not None}
    if args.cell is not None:
        cell = load_cell(args.cell, settings.ini)
        members: list[Member] = []
        for part in cell.members:
            found = part.entry
            robot = Robot.from_urdf(
                found.urdf,
                found.base,
                found.eelink,
                package_paths=found.package_paths,
                xacro_args=found.xacro_args,
            )
            x, y, z, roll, pitch, yaw = part.origin
            origin = pin.SE3(pin.rpy.rpyToMatrix(roll, pitch, yaw), np.array([x, y, z]))
            first = not members
            members.append(
                _member(
                    part.name,
                    robot,
                    origin,
                    part.port,
                    found.name,
                    part.extras,
                    part.ini,
                    first,
                    flags,
                )
            )
        return members, cell.name
    assert settings.urdf is not None
    robot = Robot.from_urdf(
        settings.urdf,
        settings.base,
        settings.eelink,
        package_paths=settings.package_paths,
        xacro_args=settings.xacro_args,
    )
    # The name the user chose; a --urdf without --robot is named by its model.
    name = robot.name if args.urdf is not None and args.robot is None else settings.robot
    entry = settings.robots.get(settings.robot)
    extras = entry.extras if entry is not None and args.urdf is None else ()
    identity = pin.SE3.Identity()
    member = _member(name, robot, identity, settings.port, name, extras, settings.ini, True, flags)
    return [member], None


def _keep(world: World, settings: Settings) -> None:
    """Where recordings go and how long trails get; ``--record NAME`` begins now."""
    TrailKeeper.of(world, settings.trail_points)
    desk = Recordings.of(world, settings.record_dir)
    if settings.record is not None:
        if Record.parse("record", [settings.record]).stop:  # the verb's rules for a name
            raise ConfigError("--record needs a name; 'stop' is not one")
        desk.start(settings.record, world.default)


async def _stop_recording(world: World) -> None:
    desk = Recordings.of(world)
    if desk.current is not None:
        done = await desk.stop("the program stopped")
        where = done.txt if done.error is None else f"{done.csv} ({done.error})"
        print(f"c2rviz: recorded {done.name}: {done.frames} frames, {where}", flush=True)
