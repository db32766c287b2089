"""NAME.html: a recording as a self-contained page with a player of its own, no server.

The page is viser's client showing a static scene (the grid, the robot as the
live page draws it, a batched node per marker shape, a hidden node per object
the recording places), built in a private offline viser server and serialized
by viser, and our player (``record_player.js`` and ``.css``, next to this
module), which poses the arm from the recording's frames in the browser
(``record_frames.chain_kinematics``: Pinocchio's numbers), shows the markers and objects at
their times, backwards too, moves the parts to each frame's poses, and gives
play/pause, seek, speed (0.25x to 4x), a frame back and on, the time shown, a readout
and plots that follow the time
shown.

Building it streams NAME.csv and NAME.txt (``record_frames``, ``record_commands``):
its memory does not grow with the recording's length, and the page keeps at most
``HTML_HZ`` frames a second (``MAX_HTML_FRAMES`` in all: a longer run is thinned
more). A recording whose files disagree, or that was cut short, opens with what
was good and a sentence saying what was not, never a blank or frozen page.

The parts (``add_parts``): each part NAME.csv has poses for (``Frames.parts``) gets a
node at ``/parts/robot/NAME`` in the world frame, its shape, size and colour from the
first NAME.txt line that added it (``Commands.parts``), with its name as a label over it,
as the live page draws parts (``cell_layers.PartsLayer``). It is placed at its first
frame's pose (hidden while it is not there); the player (``record_player.js``) moves it
to each frame's pose. A part with poses but no ``part`` line is left out, and said.
"""

from __future__ import annotations

import base64
import contextlib
import importlib.resources
import json
import logging
import os
import zlib
from pathlib import Path
from typing import Any, TextIO

import numpy as np
import pinocchio as pin

from ..collision.workcell import WorkcellObject
from ..observers.recorded import Recorded
from ..protocol.grammar import MARKER_SHAPES
from ..robot.model import Robot
from ..robot.visuals import load_link_geometry
from ..world.state import RobotState
from . import adapter
from .cell_layers import add_object
from .markers import marker_mesh
from .record_commands import Commands, read_commands
from .record_frames import POSE_COLUMNS, Frames, chain_kinematics, read_frames
from .robot_view import RobotView, node_name, wxyz

log = logging.getLogger("c2rviz.record")

_SEGMENT = "robot"  # the robot's node segment in the page (/robots/robot/...)


def write_html(recorded: Recorded, state: RobotState) -> Path:
    """Write NAME.html next to NAME.csv for the recording of ``state``'s robot; blocking
    (for a thread). Returns its path (an ``observers.recordings.Exporter``)."""
    robot = state.robot
    frames = read_frames(recorded.csv, robot.joint_names)
    base = state.origin * robot.base_placement
    if recorded.txt is None:
        why = recorded.error or "it was not written"
        commands = Commands(problems=[f"{recorded.name}.txt is missing ({why}): no markers"])
    else:
        commands = read_commands(recorded.txt, base)
    problems = [*frames.problems, *commands.problems]
    problems += _disagreements(recorded.name, robot, frames, commands, recorded.error)
    scene, nodes = _scene(recorded.name, state, frames, commands)
    problems += nodes.pop("partProblems")
    end = max(frames.end_s, commands.end_s if recorded.txt is not None else 0.0)
    meta = {
        "name": recorded.name,
        "robot": robot.name,
        "joints": [
            {
                "name": j.name,
                "prismatic": j.prismatic,
                "continuous": j.continuous,
                "lower": j.lower,
                "upper": j.upper,
            }
            for j in robot.joints
        ],
        "kinematics": chain_kinematics(robot),
        "frames": len(frames.times),
        "rows": frames.rows,
        "endS": end,
        "problems": problems,
        "shapes": list(MARKER_SHAPES),
        "objectChanges": [[t, list(ids)] for t, ids in commands.object_changes],
        "base": placement_list(base),
        **nodes,
    }
    blobs = {
        "times": frames.times.astype("<f8"),
        "values": frames.values.astype("<f4"),
        "marks": commands.marks.astype("<f8"),
    }
    path = recorded.csv.with_suffix(".html")
    part = path.with_name(f".{path.name}.part")  # then renamed: NAME.html whole, or not at all
    flags = os.O_WRONLY | os.O_CREAT | os.O_TRUNC | getattr(os, "O_NOFOLLOW", 0)
    try:
        with _sink(open(os.open(part, flags, 0o644), "w", encoding="utf-8")) as out:
            head, tail = scene.rsplit("</body>", 1)
            out.write(head)
            out.write(
                f'<script type="application/json" id="c2rviz-recording">{_json(meta)}</script>\n'
            )
            for name, array in blobs.items():
                out.write(f'<script type="application/octet-stream" id="c2rviz-{name}">')
                out.write(_packed(array))
                out.write("</script>\n")
            out.write(f"<style>{_asset('record_player.css')}</style>\n")
            out.write(f"<script>{_asset('record_player.js')}</script>\n</body>")
            out.write(tail)
        os.replace(part, path)  # a link at NAME.html is replaced, never followed
    except BaseException:  # a full disk: no page, and no part of one left to fill it
        with contextlib.suppress(OSError):
            os.unlink(part)
        raise
    for problem in problems:
        log.warning("recording %s: %s", recorded.name, problem)
    return path


def _sink(file: TextIO) -> TextIO:
    """Where the page is written: ``file`` (a test puts a disk that fills in between)."""
    return file


def _disagreements(
    name: str, robot: Robot, frames: Frames, commands: Commands, early: str | None = None
) -> list[str]:
    """Where NAME.txt and NAME.csv do not tell one recording of this robot (``early``: why
    the recording stopped early, if it did: each file then kept what reached the disk)."""
    out = []
    if commands.robot is not None and commands.robot != robot.name:
        out.append(f"{name}.txt is a recording of {commands.robot}, not of {robot.name}")
    if commands.frames is not None and frames.rows and frames.rows != commands.frames and early:
        out.append(
            f"{name}.csv holds {frames.rows} frames and {name}.txt {commands.frames}: the "
            f"recording stopped early ({early}), each file with what reached the disk"
        )
    elif commands.frames is not None and frames.rows and frames.rows != commands.frames:
        which = "cut short" if frames.rows < commands.frames else "not from this recording"
        out.append(
            f"{name}.csv holds {frames.rows} frames but {name}.txt counts {commands.frames}: "
            f"the frames were {which}"
        )
    elif commands.last_joints is not None and len(frames.times):
        last = frames.values[-1, : robot.n].astype(float)
        mine = np.asarray(commands.last_joints[: robot.n])
        if len(commands.last_joints) != robot.n or not np.allclose(
            last, mine, rtol=1e-6, atol=1e-6
        ):
            out.append(
                f"{name}.csv's last frame is not {name}.txt's last joints: the two files "
                "are not one recording"
            )
    if commands.end_s and frames.end_s > commands.end_s + 1e-3:
        out.append(
            f"{name}.csv goes on to {frames.end_s:.3f} s, past the end of {name}.txt "
            f"({commands.end_s:.3f} s)"
        )
    return out


def _scene(
    name: str, state: RobotState, frames: Frames, commands: Commands
) -> tuple[str, dict[str, Any]]:
    """The static scene as viser's page, and the nodes the player moves, by role."""
    robot, origin = state.robot, state.origin
    server = adapter.start("127.0.0.1", 0)  # offline: nothing connects to it
    try:
        server.scene.add_grid("/grid", width=4.0, height=4.0, cell_size=0.25, section_size=1.0)
        view = RobotView(server, name, robot, origin, load_link_geometry(robot.source), _SEGMENT)
        first = tuple(map(float, frames.values[0, : robot.n])) if len(frames.times) else None
        view.draw(first or robot.home)
        links = [view.link_nodes[link] for link in robot.link_names()]
        row = {node: k for k, node in enumerate(links)}  # a link's parent: the node above it
        parents = [row.get(node.rsplit("/", 1)[0], -1) for node in links]
        markers = {}
        used = {int(s) for s in commands.marks[:, 12]} if len(commands.marks) else set()
        for k in sorted(used):
            shape = MARKER_SHAPES[k]
            vertices, faces = marker_mesh(shape)
            markers[shape] = node = f"/markers/{_SEGMENT}/{shape}"
            server.scene.add_batched_meshes_simple(
                node,
                vertices,
                faces,
                batched_wxyzs=np.zeros((0, 4)),
                batched_positions=np.zeros((0, 3)),
                batched_colors=np.zeros((0, 3), dtype=np.uint8),
                lod="off",
                cast_shadow=False,
                visible=False,
            )
        objects = []
        for k, version in enumerate(commands.objects):
            node = f"{view.prefix}/objects/{k}_{node_name(version.name)}"
            x, y, z, roll, pitch, yaw = version.pose
            placement = pin.SE3(pin.rpy.rpyToMatrix(roll, pitch, yaw), np.array([x, y, z]))
            obj = WorkcellObject(version.name, version.shape, version.size, placement)
            add_object(server.scene, node, obj, robot.base_placement * placement).visible = False
            objects.append(node)
        parts, part_problems = add_parts(
            server.scene, name, frames, commands, robot.n, state.origin * robot.base_placement
        )
        _aim_camera(server, view)
        html = server.get_scene_serializer().as_html()
    finally:
        adapter.stop(server)
    return html, {
        "linkNodes": links,
        "linkParents": parents,
        "markerNodes": markers,
        "objectNodes": objects,
        "parts": parts,
        "partProblems": part_problems,
    }


def _aim_camera(server: Any, view: RobotView) -> None:
    """Look at the robot from the front right, a little above (as the live page does)."""
    reach = max(view.reach(), 0.5)
    look_at = view.origin.translation + np.array([0.0, 0.0, 0.4 * reach])
    server.initial_camera.look_at = look_at
    server.initial_camera.position = look_at + reach * np.array([1.15, 0.9, 0.45])


def _packed(array: np.ndarray) -> str:
    """``array``'s bytes, gzipped, in base64 (the page inflates them with the browser's own
    DecompressionStream)."""
    squeeze = zlib.compressobj(6, zlib.DEFLATED, 31)  # 31: a gzip stream
    data = squeeze.compress(np.ascontiguousarray(array).tobytes()) + squeeze.flush()
    return base64.b64encode(data).decode("ascii")


def _json(value: Any) -> str:
    """``value`` as JSON safe inside a <script> element (no '<' to end it early)."""
    text = json.dumps(value, allow_nan=False, separators=(",", ":"), default=_finite)
    return text.replace("<", "\\u003c").replace(">", "\\u003e").replace("&", "\\u0026")


def _finite(value: Any) -> Any:
    if isinstance(value, np.generic):
        return value.item()
    raise TypeError(f"{type(value).__name__} is not JSON")


def _asset(name: str) -> str:
    text = importlib.resources.files(__package__).joinpath(name).read_text(encoding="utf-8")
    if "</script" in text.lower():  # it is inlined in a <script> element
        raise ValueError(f"{name} must not hold '</script'")
    return text


def placement_list(placement: pin.SE3) -> list[float]:
    """``placement`` as x, y, z, qw, qx, qy, qz (the player's form)."""
    return [*map(float, placement.translation), *map(float, wxyz(placement.rotation))]


def add_parts(
    scene: Any, name: str, frames: Frames, commands: Commands, n: int, base: pin.SE3
) -> tuple[list[dict[str, Any]], list[str]]:
    """Add a node per part of ``frames`` (``n`` joints; ``base``: the base frame in the
    world) to ``scene``; return the player's description of each and the problems."""
    parts, problems = [], []
    for k, part in enumerate(frames.parts):
        column = n + len(POSE_COLUMNS) * (k + 1)
        shape = commands.parts.get(part)
        if shape is None:
            problems.append(f"{name}.txt never adds part {part!r}: it is not drawn")
            parts.append({"name": part, "column": column, "node": None})
            continue
        node = f"/parts/{_SEGMENT}/{node_name(part)}"
        common: dict[str, Any] = {"color": shape.rgb, "cast_shadow": False}
        if shape.shape == "box":
            handle = scene.add_box(node, dimensions=shape.size, **common)
        elif shape.shape == "cylinder":
            handle = scene.add_cylinder(node, radius=shape.size[0], height=shape.size[1], **common)
        else:
            handle = scene.add_icosphere(node, radius=shape.size[0], **common)
        scene.add_label(f"{node}/label", part, anchor="bottom-left")
        pose = frames.values[0, column : column + 6] if len(frames.times) else None
        if pose is not None and np.isfinite(pose).all():
            x, y, z, roll, pitch, yaw = map(float, pose)
            at = base * pin.SE3(pin.rpy.rpyToMatrix(roll, pitch, yaw), np.array([x, y, z]))
            handle.position = at.translation
            handle.wxyz = wxyz(at.rotation)
        else:
            handle.visible = False
        parts.append({"name": part, "column": column, "node": node})
    return parts, problems
