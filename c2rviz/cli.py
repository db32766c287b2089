"""``c2rviz``: load the robot, start the viewer and the command server, run until quit."""

from __future__ import annotations

import argparse
import asyncio
import ipaddress
import logging
import secrets
import signal
import sys
from collections.abc import Sequence
from pathlib import Path

from .catalogue import catalogue, listing
from .config import Settings, find_ini, load_settings, read_robots
from .errors import C2rvizError
from .robot import Robot
from .scene import NullScene, Scene
from .server import CommandServer
from .world import World

__all__ = ["build_parser", "main", "serve"]

log = logging.getLogger("c2rviz")

_STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="c2rviz",
        description="Drive a robot arm with one-line text commands over TCP and watch it "
        "move in a browser. Flags override cmdinterpreter.ini.",
    )
    add = parser.add_argument
    add(
        "--config",
        metavar="PATH",
        help="ini file (default: ./cmdinterpreter.ini, else the project's)",
    )
    add(
        "--robot",
        metavar="NAME",
        help="robot section of the ini file, or an example-robot-data "
        "arm such as ur5 or panda (default: motoman_sia20d; see --list-robots)",
    )
    add("--list-robots", action="store_true", help="list the robots --robot can name, and exit")
    add("--urdf", metavar="PATH", type=Path, help="load this URDF or .xacro instead of the robot's")
    add(
        "--package-path",
        dest="package_paths",
        metavar="DIR",
        action="append",
        help="where package://NAME/... is looked for: a folder holding packages, a package, "
        "or NAME=DIR (repeatable; then ROS_PACKAGE_PATH, then upward from the URDF)",
    )
    add(
        "--xacro-arg",
        dest="xacro_args",
        metavar="NAME:=VALUE",
        action="append",
        help="an argument for a .xacro file (repeatable)",
    )
    add("--base", metavar="LINK", help="first link of the chain")
    add("--eelink", metavar="LINK", help="end-effector link: last link of the chain")
    add("--host", help="address for the command server (default 127.0.0.1)")
    add("--port", type=int, help="command port (default 31000; 0 picks a free one)")
    add(
        "--viser-host",
        dest="viewer_host",
        metavar="HOST",
        help="address for the browser view (default 127.0.0.1)",
    )
    add(
        "--viser-port",
        dest="viewer_port",
        type=int,
        metavar="PORT",
        help="port for the browser view (default 8080)",
    )
    add(
        "--viewer-origin",
        dest="viewer_origins",
        metavar="ORIGIN",
        action="append",
        help="an origin besides the viewer's own allowed to open its websocket, e.g. "
        "https://robot.example.org behind a reverse proxy (repeatable)",
    )
    add(
        "--viewer-token",
        metavar="TOKEN",
        help="the page and its websocket need ?token=TOKEN (the printed URL carries it; "
        "default: none on loopback, else one generated at start)",
    )
    add("--max-viewers", type=int, metavar="N", help="viewer tabs at once (default 16)")
    add("--hz", type=float, help="most scene updates per second (default 100)")
    add(
        "--motion",
        choices=("off", "on", "follow"),
        help="how new connections' moves are shown: off (at once, the default), on (travel, "
        "reply on arrival) or follow (travel, reply at once)",
    )
    add("--speed", type=float, metavar="P", help="new connections' speed, %% of the limits (50)")
    add(
        "--no-viewer",
        dest="viewer",
        action="store_const",
        const=False,
        help="run the command server alone",
    )
    add("--max-clients", type=int, metavar="N", help="clients at once (default 64)")
    add("--max-line", type=int, metavar="BYTES", help="longest line (default 8192)")
    add(
        "--max-unread",
        type=int,
        metavar="BYTES",
        help="unread replies before a client is dropped (default 1 MiB)",
    )
    add(
        "--partial-timeout",
        dest="partial_timeout_s",
        type=float,
        metavar="S",
        help="seconds a started line may stay unfinished (default 10)",
    )
    add(
        "--max-sleep",
        dest="max_sleep_s",
        type=float,
        metavar="S",
        help="longest sleep command (default 3600)",
    )
    add("-v", "--verbose", action="store_true", help="log every connection")
    return parser


def _is_loopback(host: str) -> bool:
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


def _open_scene(settings: Settings, world: World) -> Scene:
    if not settings.viewer:
        return NullScene()
    from .view.policy import DoorPolicy
    from .viewer import ViserScene  # viser is heavy: import only when it is used

    token = settings.viewer_token
    if token is None and not _is_loopback(settings.viewer_host):
        token = secrets.token_urlsafe(16)
    policy = DoorPolicy(settings.viewer_origins, token, settings.max_viewers)
    return ViserScene(world, settings.viewer_host, settings.viewer_port, settings.hz, policy=policy)


async def serve(settings: Settings, robot: Robot) -> int:
    """Run the viewer and the command server until ``quit``, SIGINT, SIGTERM or SIGHUP."""
    loop = asyncio.get_running_loop()
    stop = asyncio.Event()
    world = World(robot, hz=settings.hz, defaults=settings.session)
    try:
        scene = _open_scene(settings, world)
    except OSError as exc:
        print(
            f"c2rviz: cannot serve the viewer on {settings.viewer_host}:{settings.viewer_port}: "
            f"{exc.strerror or exc}",
            file=sys.stderr,
        )
        return 2
    except C2rvizError as exc:
        print(f"c2rviz: {exc}", file=sys.stderr)
        return 2
    world.add_observers([scene])
    scene.start(world, loop)
    server = CommandServer(world, settings.limits, on_quit=stop.set)
    try:
        host, port = await server.start(settings.host, settings.port)
    except OSError as exc:
        print(
            f"c2rviz: cannot listen on {settings.host}:{settings.port}: {exc.strerror}",
            file=sys.stderr,
        )
        scene.stop()
        return 2
    for sig in _STOP_SIGNALS:
        loop.add_signal_handler(sig, stop.set)
    names = " ".join(robot.joint_names)
    print(
        f"c2rviz: {robot.name}, chain {robot.base} -> {robot.eelink}, joints 0..{robot.n - 1}: "
        f"{names}",
        flush=True,
    )
    print(f"c2rviz: commands on {host}:{port} (try: nc {host} {port}, then 'help')", flush=True)
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
        await server.stop()
        world.travels.stop_all()
        scene.stop()
    print("c2rviz: stopped", flush=True)
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``c2rviz`` command; returns the exit status."""
    args = build_parser().parse_args(argv)
    logging.basicConfig(
        level=logging.INFO if args.verbose else logging.WARNING,
        format="c2rviz: %(levelname)s: %(message)s",
    )
    overrides = {
        k: v for k, v in vars(args).items() if k not in ("config", "verbose", "list_robots")
    }
    try:
        if args.list_robots:
            ini = find_ini(args.config)
            print(listing(catalogue(read_robots(ini), ini).values()))
            return 0
        settings = load_settings(find_ini(args.config), overrides)
        assert settings.urdf is not None
        robot = Robot.from_urdf(
            settings.urdf,
            settings.base,
            settings.eelink,
            package_paths=settings.package_paths,
            xacro_args=settings.xacro_args,
        )
    except C2rvizError as exc:
        print(f"c2rviz: {exc}", file=sys.stderr)
        return 2
    try:
        return asyncio.run(serve(settings, robot))
    except KeyboardInterrupt:  # a second Ctrl-C while stopping
        return 130


if __name__ == "__main__":
    sys.exit(main())
