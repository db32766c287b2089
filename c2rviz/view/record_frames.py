"""The recorded page's frames: NAME.csv read (streamed, thinned to what the page shows,
checked), and the chain's forward kinematics that pose the arm from them.

``read_frames`` reads the file in ``CHUNK_BYTES`` pieces, so memory does not grow
with the recording's length: of every row it reads only the time, and it keeps
the first row of each ``1 / HTML_HZ`` of the recording (wider for a recording
longer than ``MAX_HTML_FRAMES`` frames at that rate), and the last row. Kept rows
are parsed whole and checked: the header names the robot's joints, every row has
its number of values, all finite, and time never goes back. After the tool pose the
header may name parts' poses (``NAME.x`` .. ``NAME.yaw``, six columns a part: the
recorder's ``observers.recorded.csv_columns``); a part's empty cells (it was
removed) are read as NaN. Anything wrong ends
the reading there, with a sentence in ``problems`` that the page shows: the page
opens with what was good and says what was not, never blank or frozen.

The recorded page has no server: it poses each link from the recording's joint
values in the browser. Pinocchio stays the one source of truth: ``chain_kinematics``
reads, from the Pinocchio model at ``Robot.home``, each joint's placement in its
parent's frame and, for a joint that a chain value moves (the chain's joints, and
mimic joints through their leader), the twist per unit of that value, found by
moving the value and taking ``log6`` of the change (exact for the revolute and
prismatic joints a chain holds). A joint's placement for chain values ``q`` is
then ``placement * exp6(twist * (q[chain] - home))``, a link's pose its joint's
pose times the link's placement: ``pose_links`` does it in numpy, the page's
player the same in JavaScript, and a test checks both against Pinocchio.

Placements are ``[x, y, z, qw, qx, qy, qz]`` [m].
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin

from ..errors import RobotError
from ..robot.model import Robot

HTML_HZ = 30.0
"""Most frames a second kept for the page."""
MAX_HTML_FRAMES = 120_000
"""Most frames kept (66 minutes at ``HTML_HZ``); a longer recording is thinned more."""
CHUNK_BYTES = 1 << 20
"""The piece of NAME.csv read at a time [bytes]."""
POSE_COLUMNS = ("x", "y", "z", "roll", "pitch", "yaw")
_TAIL_BYTES = 1 << 16


@dataclass
class Frames:
    """The frames kept for the page.

    Attributes:
        times: Each kept frame's time [s from the start], shape (k,).
        values: Its joints [rad or m] then the tool pose x, y, z [m], roll, pitch, yaw
            [rad], shape (k, n + 6), float32.
            Then six per part in ``parts``: its pose x, y, z [m], roll, pitch, yaw [rad]
            in the base frame, NaN while it is not there.
        rows: Good rows read (every one, kept or not).
        parts: The parts whose poses follow the tool pose, in the columns' order.
        problems: What was wrong, one sentence each (empty: nothing).
    """

    times: np.ndarray
    values: np.ndarray
    rows: int = 0
    problems: list[str] = field(default_factory=list)
    parts: list[str] = field(default_factory=list)

    @property
    def end_s(self) -> float:
        """The last good frame's time [s] (0 with none)."""
        return float(self.times[-1]) if len(self.times) else 0.0


def read_frames(path: Path, joint_names: Sequence[str]) -> Frames:
    """Read ``path`` (NAME.csv of a robot with ``joint_names``) as ``Frames``."""
    n = len(joint_names)
    width = 1 + n + len(POSE_COLUMNS)
    empty = Frames(np.empty(0), np.empty((0, width - 1), dtype=np.float32))
    name = path.name
    try:
        with open(path, "rb") as file:
            header = file.readline()
            expected = ",".join(("time", *joint_names, *POSE_COLUMNS))
            got = header.decode("ascii", "replace").strip()
            if not header:
                empty.problems.append(f"{name} is empty: nothing was recorded")
                return empty
            parts = _part_names(got[len(expected) :]) if got.startswith(expected) else None
            if parts is None:
                empty.problems.append(
                    f"{name} is not this robot's: its columns are {_cut(got)}, "
                    f"the robot's are {_cut(expected)}"
                )
                return empty
            step = max(1.0 / HTML_HZ, _last_time(path) / MAX_HTML_FRAMES)
            frames = _Reader(name, width + 6 * len(parts), step, width).read(file)
            frames.parts = parts
            return frames
    except OSError as exc:
        empty.problems.append(f"{name} cannot be read: {exc.strerror or exc}")
        return empty


class _Reader:
    """One streaming pass over the rows after the header."""

    def __init__(self, name: str, width: int, step: float, checked: int) -> None:
        self.name = name
        self.width = width
        self.checked = checked  # the columns that must be finite (the parts' may be empty)
        self.step = step
        self.line = 1  # the header's
        self.rows = 0
        self.last_bin = -math.inf
        self.last_time = -math.inf
        self.last_row: bytes | None = None
        self.last_kept = False
        self.kept_times: list[np.ndarray] = []
        self.kept: list[np.ndarray] = []
        self.problems: list[str] = []

    def read(self, file: object) -> Frames:
        carry = b""
        while True:
            chunk = file.read(CHUNK_BYTES)  # type: ignore[attr-defined]
            if not chunk:
                break
            chunk = carry + chunk
            cut = chunk.rfind(b"\n") + 1
            carry, chunk = chunk[cut:], chunk[:cut]
            if chunk and not self._chunk(chunk.split(b"\n")[:-1]):
                carry = b""
                break
        if carry.strip():
            self._stop(
                self.line + 1,
                "ends in a partial row: the recording was cut short",
            )
        if self.last_row is not None and not self.last_kept:
            row = np.array([cell or b"nan" for cell in self.last_row.split(b",")], dtype=float)
            self.kept_times.append(row[:1])
            self.kept.append(row[None, 1:].astype(np.float32))
        times = np.concatenate(self.kept_times) if self.kept else np.empty(0)
        values = (
            np.concatenate(self.kept)
            if self.kept
            else np.empty((0, self.width - 1), dtype=np.float32)
        )
        frames = Frames(times, values, self.rows, self.problems)
        if not self.rows and not self.problems:
            self.problems.append(f"{self.name} holds no frames: nothing was recorded")
        return frames

    def _chunk(self, lines: list[bytes]) -> bool:
        """Take a chunk's whole lines; False once a bad one ends the reading."""
        commas = self.width - 1
        bad = next((i for i, line in enumerate(lines) if line.count(b",") != commas), None)
        if bad is not None:
            self._take(lines[:bad])
            count = lines[bad].count(b",") + 1
            self._stop(self.line + 1, f"has {count} values in a row of {self.width}")
            return False
        return self._take(lines)

    def _take(self, lines: list[bytes]) -> bool:
        if not lines:
            return True
        try:
            times = np.array([line[: line.find(b",")] for line in lines], dtype=float)
        except ValueError:
            return self._one_by_one(lines)
        order = np.diff(times, prepend=self.last_time)
        bad = np.flatnonzero(~np.isfinite(times) | (order < 0))
        if len(bad):
            k = int(bad[0])
            self._take(lines[:k])
            self._stop(self.line + 1, "goes back in time or has a time that is not a number")
            return False
        bins = np.floor(times / self.step)
        keep = np.flatnonzero(np.diff(bins, prepend=self.last_bin) != 0)
        if len(keep):
            joined = b",".join([lines[i] for i in keep])
            try:
                cells = joined.split(b",")
                if self.width > self.checked:  # a removed part's empty cells
                    cells = [cell or b"nan" for cell in cells]
                values = np.array(cells, dtype=float).reshape(len(keep), -1)
            except ValueError:
                return self._one_by_one(lines)
            if not np.isfinite(values[:, : self.checked]).all():
                return self._one_by_one(lines)
            self.kept_times.append(values[:, 0].copy())
            self.kept.append(values[:, 1:].astype(np.float32))
        self.rows += len(lines)
        self.line += len(lines)
        self.last_bin, self.last_time = float(bins[-1]), float(times[-1])
        self.last_row = lines[-1]
        self.last_kept = bool(len(keep)) and int(keep[-1]) == len(lines) - 1
        return True

    def _one_by_one(self, lines: list[bytes]) -> bool:
        """The slow way through a chunk with a bad row: take the good ones before it."""
        for k, line in enumerate(lines):
            try:
                cells = line.split(b",")
                checked, rest = cells[: self.checked], cells[self.checked :]
                values = np.array(checked + [cell or b"nan" for cell in rest], dtype=float)
            except ValueError:
                values = np.array([math.nan])
            if not np.isfinite(values[: self.checked]).all():
                self._take(lines[:k])
                self._stop(self.line + 1, "has a value that is not a finite number")
                return False
        return self._take(lines)  # (not reached for a chunk that failed to parse)

    def _stop(self, line: int, what: str) -> None:
        shown = f"{self.last_time:.3f} s" if self.rows else "nothing"
        self.problems.append(
            f"{self.name} line {line} {what}; the page shows the {self.rows} good rows "
            f"before it (up to {shown})"
        )


def _last_time(path: Path) -> float:
    """The time of the last whole row of ``path`` [s] (0 if none can be read)."""
    size = os.path.getsize(path)
    with open(path, "rb") as file:
        file.seek(max(0, size - _TAIL_BYTES))
        tail = file.read().split(b"\n")
    for line in reversed(tail[:-1]):  # whole lines only
        try:
            return max(float(line[: line.find(b",")]), 0.0)
        except ValueError:
            continue
    return 0.0


def _part_names(columns: str) -> list[str] | None:
    """The parts named by the header's ``columns`` after the tool pose (``,NAME.x`` ..
    ``,NAME.yaw`` each), or None if they are not such columns."""
    if not columns:
        return []
    names = columns[1:].split(",") if columns.startswith(",") else []
    if not names or len(names) % len(POSE_COLUMNS):
        return None
    parts = []
    for k in range(0, len(names), len(POSE_COLUMNS)):
        part = names[k].rsplit(".", 1)[0]
        if names[k : k + len(POSE_COLUMNS)] != [f"{part}.{a}" for a in POSE_COLUMNS]:
            return None
        parts.append(part)
    return parts


def _cut(text: str, limit: int = 120) -> str:
    return text if len(text) <= limit else text[: limit - 3] + "..."


_DELTA = 0.5  # how far a chain value is moved to read its joints' twists [rad or m]


def _placement(m: pin.SE3) -> list[float]:
    x, y, z, w = pin.Quaternion(m.rotation).coeffs()  # pinocchio: x, y, z, w
    return [*map(float, m.translation), float(w), float(x), float(y), float(z)]


def chain_kinematics(robot: Robot) -> dict[str, Any]:
    """The chain's kinematics as plain numbers (JSON for the page).

    Returns:
        ``joints``: one per Pinocchio joint after the universe, in model order, each
        ``{"parent": index (0: the universe, else 1 + position in this list), "placement",
        "chain": the chain value that moves it (-1: none), "twist": [vx, vy, vz, wx, wy,
        wz] per unit of it, "home": that value at home}``; ``links``: one per link the
        page draws (``Robot.link_names()``), ``{"name", "joint", "placement"}``.

    Raises:
        RobotError: a joint moved by two chain values (no chain the page can draw).
    """
    model = robot.model
    data = model.createData()
    home = list(robot.home)
    pin.forwardKinematics(model, data, robot.configuration(home))
    at_home = [data.liMi[j].copy() for j in range(model.njoints)]
    drivers: dict[int, tuple[int, np.ndarray]] = {}
    for c in range(robot.n):
        q = list(home)
        q[c] += _DELTA
        pin.forwardKinematics(model, data, robot.configuration(q))
        for j in range(1, model.njoints):
            change = at_home[j].actInv(data.liMi[j])
            if change.isIdentity(1e-12):
                continue
            if j in drivers:
                raise RobotError(f"joint {model.names[j]!r} moves with two chain joints")
            drivers[j] = (c, pin.log6(change).vector / _DELTA)
    joints = []
    for j in range(1, model.njoints):
        c, twist = drivers.get(j, (-1, np.zeros(6)))
        joints.append(
            {
                "parent": int(model.parents[j]),
                "placement": _placement(at_home[j]),
                "chain": c,
                "twist": [float(v) for v in twist],
                "home": float(home[c]) if c >= 0 else 0.0,
            }
        )
    links = []
    for link in robot.link_names():
        frame = model.frames[model.getFrameId(link, pin.BODY)]
        joint, where = int(frame.parentJoint), _placement(frame.placement)
        links.append({"name": link, "joint": joint, "placement": where})
    return {"joints": joints, "links": links}


def pose_links(kinematics: dict[str, Any], q: Sequence[float]) -> list[pin.SE3]:
    """Each link's pose in the model's root frame for chain values ``q`` [rad or m], from
    ``chain_kinematics``' numbers alone (what the page computes)."""

    def se3(p: Sequence[float]) -> pin.SE3:
        x, y, z, w, qx, qy, qz = p
        return pin.SE3(pin.Quaternion(w, qx, qy, qz).toRotationMatrix(), np.array([x, y, z]))

    poses = [pin.SE3.Identity()]
    for joint in kinematics["joints"]:
        local = se3(joint["placement"])
        if joint["chain"] >= 0:
            amount = q[joint["chain"]] - joint["home"]
            local = local * pin.exp6(pin.Motion(np.asarray(joint["twist"]) * amount))
        poses.append(poses[joint["parent"]] * local)
    return [poses[link["joint"]] * se3(link["placement"]) for link in kinematics["links"]]
