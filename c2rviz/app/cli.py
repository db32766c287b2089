"""``c2rviz``: the flags, the settings, and then the program (``program.serve``).

A page process the flags or the ini ask for is forked once the settings are read and the
robots loaded, before the program starts its loop (``view.page_start.fork``).
"""

from __future__ import annotations

import argparse
import asyncio
import logging
import sys
from collections.abc import Sequence
from pathlib import Path

from ..collision.geometry import read_srdf
from ..errors import C2rvizError
from ..ini import find_ini
from ..robot.catalogue import catalogue, listing
from .config import LIGHTINGS, MOTION_FLAGS, load_settings, read_robots
from .members import members
from .program import serve

log = logging.getLogger("c2rviz")


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
    add(
        "--cell",
        metavar="NAME|PATH",
        help="serve the robots of [cell:NAME] in the ini (or of the ini file PATH), each on "
        "its own port, in one world and one page (docs/cells.md)",
    )
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
    add(
        "--port",
        type=int,
        help="command port (default 31000; 0 picks a free one); with --cell the first "
        "robot's, the others at the next ports",
    )
    add(
        "--crcl-port",
        type=int,
        metavar="PORT",
        help="port for NIST's CRCL (XML commands, docs/crcl.md; default 64444, a cell's "
        "robots this one and the next; 0 picks free ones)",
    )
    add("--no-crcl", dest="crcl", action="store_const", const=False, help="no CRCL door")
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
    add(
        "--viewer-lighting",
        choices=LIGHTINGS,
        help="studio (the default: an environment map and shadows) or plain (lights only: "
        "nearly the same look, a third of the CPU in a browser without a GPU; docs/page.md)",
    )
    add(
        "--rosbridge-port",
        type=int,
        metavar="PORT",
        help="port of the rosbridge websocket for ROS tools (roslibpy, roslibjs) on "
        "--host (default 9090; 0 picks a free one; docs/rosbridge.md)",
    )
    add(
        "--no-rosbridge",
        dest="rosbridge",
        action="store_const",
        const=False,
        help="serve no rosbridge websocket",
    )
    add("--hz", type=float, help="most scene updates per second (default 100)")
    add(
        "--clock",
        metavar="real|scaled:N|virtual",
        help="the world's time: real (the default); scaled:N runs N times faster; virtual "
        "jumps ahead whenever every client waits on the clock (sleep, wait, an arrival), "
        "so a program runs as fast as the CPU allows (docs/testing.md)",
    )
    add(
        "--motion",
        choices=("off", "on", "follow"),
        help="how new connections' moves are shown: off (at once, the default), on (travel, "
        "reply on arrival) or follow (travel, reply at once)",
    )
    add("--speed", type=float, metavar="P", help="new connections' speed, %% of the limits (50)")
    add(
        "--guard",
        choices=("off", "on", "plan"),
        help="new connections refuse colliding targets and paths (on), or plan joint-space "
        "moves around what they would hit (plan); default off",
    )
    add(
        "--plan-timeout",
        dest="plan_timeout_s",
        type=float,
        metavar="S",
        help="most time a plan searches (default 1 s; 0.001..60)",
    )
    add(
        "--seed",
        dest="plan_seed",
        type=int,
        metavar="N",
        help="seed of the planner and of rand, so a run repeats (default: a fresh one)",
    )
    add(
        "--plan-step",
        dest="plan_step_deg",
        type=float,
        metavar="DEG",
        help="most a joint turns between two checks of a path (default 1 degree; 0.01..10)",
    )
    add(
        "--plan-tool-step",
        dest="plan_tool_step_mm",
        type=float,
        metavar="MM",
        help="most the tool travels between two checks of a path (default 5 mm; 0.1..100)",
    )
    add("--srdf", metavar="FILE", type=Path, help="SRDF whose disable_collisions are honoured")
    add("--max-objects", type=int, metavar="N", help="workcell objects per robot (default 100)")
    for key, unit in (("velocity", "s"), ("acceleration", "s^2"), ("jerk", "s^3")):
        add(
            f"--max-{key}",
            metavar="V[,V...]",
            help=f"every robot's {key} limit, rad or m per {unit}: one number, or one per joint "
            "(over the ini's; default: "
            + {
                "velocity": "the URDF's",
                "acceleration": "2 x velocity",
                "jerk": "10 x velocity",
            }[key]
            + ")",
        )
    add(
        "--no-viewer",
        dest="viewer",
        action="store_const",
        const=False,
        help="run the command server alone",
    )
    add(
        "--page-process",
        action="store_const",
        const=True,
        help="serve the page from a process of its own, so drawing never delays a command "
        "(ini: page_process = on; docs/page.md)",
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
    add(
        "--record",
        metavar="NAME",
        help="record from start to exit into the recording folder: NAME.txt (a command file "
        "c2rviz-play replays), NAME.csv (one row per frame), NAME.html (a page that plays it) "
        "and NAME/ (a rosbag2 bag); in a cell every robot: NAME.ROBOT.txt, .csv, .html each "
        "and one bag NAME/ (docs/recording.md)",
    )
    add(
        "--record-overwrite",
        action="store_const",
        const=True,
        help="--record may replace an existing NAME (default: refuse to start)",
    )
    add(
        "--record-dir",
        metavar="DIR",
        help="where recordings go (default ./recordings; created when needed)",
    )
    add("-v", "--verbose", action="store_true", help="log every connection")
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``c2rviz`` command; returns the exit status."""
    args = build_parser().parse_args(argv)
    logging.basicConfig(
        level=logging.INFO if args.verbose else logging.WARNING,
        format="c2rviz: %(levelname)s: %(message)s",
    )
    overrides = {
        k: v
        for k, v in vars(args).items()
        if k not in ("config", "verbose", "list_robots", *MOTION_FLAGS)
    }
    overrides["motion_flags"] = tuple(
        (k, getattr(args, k)) for k in MOTION_FLAGS if getattr(args, k) is not None
    )
    overrides["robot_flag"] = args.robot is not None
    overrides["port_flag"] = args.port is not None
    overrides["urdf_flag"] = args.urdf is not None
    try:
        if args.list_robots:
            ini = find_ini(args.config)
            print(listing(catalogue(read_robots(ini), ini).values()))
            return 0
        settings = load_settings(find_ini(args.config), overrides)
        robots, cell = members(settings)
        if settings.srdf is not None:
            read_srdf(settings.srdf)  # a bad SRDF stops here, with its one sentence
    except C2rvizError as exc:
        print(f"c2rviz: {exc}", file=sys.stderr)
        return 2
    spawned = None
    if settings.page_process and settings.viewer:
        from ..view import page_start  # (a program without a viewer loads no view module)

        # What both processes need is loaded: the page process starts from it.
        spawned = page_start.fork()
    try:
        return asyncio.run(
            serve(settings, robots, cell, page_process=settings.page_process, spawned=spawned)
        )
    except KeyboardInterrupt:  # a second Ctrl-C while stopping
        return 130
    finally:
        if spawned is not None:
            page_start.close(spawned)  # if it never got its hello (a door could not open)


if __name__ == "__main__":
    sys.exit(main())
