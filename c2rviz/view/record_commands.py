"""NAME.txt read for the recorded page: its markers and objects in time, and its checks.

``read_commands`` streams the command file the recorder wrote (``radians``,
``motion off``, then ``joints``, ``sleep``, ``mark``, ``color``, ``marker``,
``clear`` and, when a recording holds them, ``object``, ``part`` and ``grip`` lines) in
``record_frames.CHUNK_BYTES`` pieces. Most of a long recording is ``joints`` and
``sleep`` lines: a piece with nothing else in it costs a regular-expression pass
to add up its sleeps. The rest is parsed line by line (``protocol.parse_line``).

It returns the markers' changes and the objects' changes, each timed by the
sleeps before it (at most ``MAX_HTML_MARKS`` and ``MAX_HTML_OBJECTS`` distinct
objects; the rest is left out and said), each part's shape (its first ``part`` line
adding it: NAME.csv has its poses), the header's robot and duration, the
time the sleeps add up to and the last ``joints`` line, which the page checks
against NAME.csv: a command file that does not belong to its frames is said in
the page.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pinocchio as pin

from ..errors import C2rvizError
from ..protocol.grammar import MARKER_SHAPES, parse_line
from ..protocol.verbs.parts import PartEdit
from ..protocol.verbs.scene import ObjectEdit
from ..protocol.verbs.seed import Clear, Color, Mark, MarkerShape, Sleep, Units
from .record_frames import CHUNK_BYTES

MAX_HTML_MARKS = 100_000
"""Most marker changes (a mark, a clear) the page holds; later ones are left out."""
MAX_HTML_OBJECTS = 256
"""Most distinct objects (a name with a shape, size and pose) the page holds."""
PART_RGB = (0.85, 0.55, 0.2)
"""A part's colour when its line gives none (the world's default, ``world.parts``)."""
_SLEEP = re.compile(rb"^sleep ([0-9.eE+-]+)\r?$", re.M)
_OTHER = re.compile(rb"^(?!joints |sleep |#)[^\n]", re.M)
_HEADER_ROBOT = re.compile(r"^# robot: (.*)$")
_HEADER_TIME = re.compile(r"^# recorded: .*?, ([0-9.]+) s, (\d+) frames")


@dataclass(frozen=True)
class ObjectVersion:
    """An object as a command placed it: name, shape, size [m], pose in the base frame
    (x, y, z [m], roll, pitch, yaw [rad])."""

    name: str
    shape: str
    size: tuple[float, ...]
    pose: tuple[float, float, float, float, float, float]


@dataclass(frozen=True)
class PartShape:
    """A part as its first ``part`` line added it: shape (box, cylinder, sphere), size [m]
    and colour (r, g, b in 0..1)."""

    shape: str
    size: tuple[float, ...]
    rgb: tuple[float, float, float]


@dataclass
class Commands:
    """What NAME.txt says besides the joints.

    Attributes:
        robot: The header's ``# robot:`` (None: no header).
        duration_s: The header's recorded time [s] (None: no header).
        frames: The header's frame count (None: no header).
        end_s: The time its sleeps add up to [s].
        last_joints: The values of its last ``joints`` line [rad or m], or None.
        marks: Marker changes, one row each: time [s], kind (0 a mark, 1 a clear), x, y, z
            [m, world frame], w, x, y, z (orientation), r, g, b (0..1), shape (index in
            ``MARKER_SHAPES``); float64, shape (m, 13).
        objects: The distinct objects, in order of first appearance.
        object_changes: (time [s], the objects there from then on, as indices into
            ``objects``), in time order.
        parts: Each part's shape by name, from the first line that added it.
        problems: What was wrong, one sentence each.
    """

    robot: str | None = None
    duration_s: float | None = None
    frames: int | None = None
    end_s: float = 0.0
    last_joints: tuple[float, ...] | None = None
    marks: np.ndarray = field(default_factory=lambda: np.empty((0, 13)))
    objects: list[ObjectVersion] = field(default_factory=list)
    object_changes: list[tuple[float, tuple[int, ...]]] = field(default_factory=list)
    parts: dict[str, PartShape] = field(default_factory=dict)
    problems: list[str] = field(default_factory=list)


def read_commands(path: Path, base: pin.SE3) -> Commands:
    """Read ``path`` (NAME.txt); ``base`` is the robot's base frame in the world frame."""
    reader = _Reader(path.name, base)
    try:
        with open(path, "rb") as file:
            carry = b""
            while chunk := file.read(CHUNK_BYTES):
                chunk = carry + chunk
                cut = chunk.rfind(b"\n") + 1
                carry, chunk = chunk[cut:], chunk[:cut]
                reader.chunk(chunk)
            if carry.strip():
                reader.problems.append(
                    f"{path.name} ends in a partial line: the recording was cut short"
                )
    except OSError as exc:
        reader.problems.append(f"{path.name} cannot be read: {exc.strerror or exc}")
    return reader.result()


class _Reader:
    def __init__(self, name: str, base: pin.SE3) -> None:
        self.name = name
        self.base = base
        self.out = Commands()
        self.problems = self.out.problems
        self.t = 0.0
        self.rgb = (1.0, 0.0, 0.0)  # a replaying session's style
        self.shape = 0
        self.angle = 1.0  # the recorder writes radians; a hand-made file may say degrees
        self.marks: list[list[float]] = []
        self.shown: dict[str, int] = {}  # object name -> version index
        self.versions: dict[ObjectVersion, int] = {}
        self.last_joints: bytes | None = None
        self.header = True
        self.dropped_marks = 0
        self.dropped_objects = 0

    def chunk(self, chunk: bytes) -> None:
        if self.header or _OTHER.search(chunk) is not None:
            for line in chunk.split(b"\n")[:-1]:
                self.line(line)
            return
        self.t += sum(map(float, _SLEEP.findall(chunk)))
        last = chunk.rfind(b"joints ", 0)
        while last > 0 and chunk[last - 1] != 10:  # "joints " at a line's start only
            last = chunk.rfind(b"joints ", 0, last)
        if last >= 0:
            self.last_joints = chunk[last : chunk.find(b"\n", last)]

    def line(self, raw: bytes) -> None:
        text = raw.decode("ascii", "replace").rstrip("\r")
        if text.startswith("#"):
            self._header(text)
            return
        self.header = False
        if text.startswith("joints "):
            self.last_joints = raw
            return
        if text.startswith("sleep "):
            try:
                self.t += float(text[6:])
            except ValueError:
                self.problems.append(f"{self.name}: a bad sleep line {text[:40]!r}")
            return
        if not text.strip():
            return
        try:
            command = parse_line(text)
        except C2rvizError as exc:
            if len(self.problems) < 10:
                self.problems.append(f"{self.name}: a line that is not a command: {exc}")
            return
        if isinstance(command, Sleep):
            self.t += command.seconds
        elif isinstance(command, Units):
            self.angle = np.pi / 180.0 if command.degrees else 1.0
        elif isinstance(command, Color):
            self.rgb = command.rgb
        elif isinstance(command, MarkerShape):
            self.shape = MARKER_SHAPES.index(command.shape)
        elif isinstance(command, Clear):
            self._mark(1.0, (0.0,) * 7)
        elif isinstance(command, Mark) and command.pose is not None:
            x, y, z, roll, pitch, yaw = command.pose
            a = self.angle
            pose = pin.SE3(pin.rpy.rpyToMatrix(roll * a, pitch * a, yaw * a), np.array([x, y, z]))
            placement = pose if command.in_world else self.base * pose
            qx, qy, qz, qw = map(float, pin.Quaternion(placement.rotation).coeffs())
            self._mark(0.0, (*map(float, placement.translation), qw, qx, qy, qz))
        elif isinstance(command, ObjectEdit):
            self._object(command)
        elif isinstance(command, PartEdit) and self._new_part(command):
            rgb = command.rgb if command.rgb is not None else PART_RGB
            self.out.parts[command.name] = PartShape(command.shape, command.size, rgb)

    def _new_part(self, command: PartEdit) -> bool:
        """Whether ``command`` adds a part not seen before."""
        return command.shape in ("box", "cylinder", "sphere") and command.name not in self.out.parts

    def _header(self, text: str) -> None:
        if m := _HEADER_ROBOT.match(text):
            self.out.robot = m.group(1).strip()
        elif m := _HEADER_TIME.match(text):
            self.out.duration_s, self.out.frames = float(m.group(1)), int(m.group(2))

    def _mark(self, kind: float, where: tuple[float, ...]) -> None:
        if len(self.marks) >= MAX_HTML_MARKS:
            self.dropped_marks += 1
            return
        self.marks.append([self.t, kind, *where, *self.rgb, float(self.shape)])

    def _object(self, command: ObjectEdit) -> None:
        if command.shape == "remove":
            if command.name == "all":
                self.shown.clear()
            else:
                self.shown.pop(command.name, None)
        else:
            x, y, z, roll, pitch, yaw = command.pose
            a = self.angle
            pose = (x, y, z, roll * a, pitch * a, yaw * a)
            version = ObjectVersion(command.name, command.shape, command.size, pose)
            index = self.versions.get(version)
            if index is None:
                if len(self.versions) >= MAX_HTML_OBJECTS:
                    self.dropped_objects += 1
                    return
                index = self.versions[version] = len(self.versions)
            self.shown[command.name] = index
        self.out.object_changes.append((self.t, tuple(self.shown.values())))

    def result(self) -> Commands:
        out = self.out
        out.end_s = self.t
        out.marks = np.array(self.marks, dtype=float).reshape(-1, 13)
        out.objects = list(self.versions)
        if self.last_joints is not None:
            try:
                values = self.last_joints.decode("ascii").split(None, 1)[1]
                out.last_joints = tuple(float(v) for v in values.split(","))
            except (ValueError, IndexError, UnicodeDecodeError):
                self.problems.append(f"{self.name}: its last joints line is damaged")
        if self.dropped_marks:
            self.problems.append(
                f"{self.name} has {self.dropped_marks} more marker changes than the page "
                f"holds ({MAX_HTML_MARKS}); they are left out"
            )
        if self.dropped_objects:
            self.problems.append(
                f"{self.name} places more distinct objects than the page holds "
                f"({MAX_HTML_OBJECTS}); {self.dropped_objects} changes are left out"
            )
        return out
