"""A command file, read with the server's own parser and checked before anything is sent.

``load_script`` parses every line with ``c2rviz.protocol.parse_line``, so a typo
on line 40 is reported as ``file:40: error: ...`` while the robot is still where
it was; ``check_robot`` then checks ``joints`` counts and ``move`` indices
against the server's robot, and ``robot_mismatch`` compares the file's
``# robot: NAME`` line with it. ``waits_for_the_arm`` and ``motion_after`` say
which lines are answered on arrival. Pure: no sockets, nothing printed.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import C2rvizError, JointCountError, JointIndexError
from ..protocol.grammar import Command, parse_line
from ..protocol.verbs.cartesian import MoveL, MoveTo
from ..protocol.verbs.connection import Bye, Quit
from ..protocol.verbs.joints import Home, Joints, Move, Rand
from ..protocol.verbs.markers import Clear
from ..protocol.verbs.motion import MotionMode, Stop, Wait

__all__ = [
    "Script",
    "ScriptLine",
    "check_robot",
    "load_script",
    "motion_after",
    "robot_mismatch",
    "waits_for_the_arm",
]

_MOVES = (Joints, Move, Home, Rand, Clear, MoveTo, MoveL)
"""Commands whose reply comes on arrival with ``motion on``."""


_ROBOT_HEADER = re.compile(r"#\s*robot:\s*([A-Za-z0-9_.-]+)\s*", re.IGNORECASE)


@dataclass(frozen=True, slots=True)
class ScriptLine:
    """One command line of a file."""

    number: int
    """Line number in the file, from 1."""
    text: str
    """The line as written (without its newline)."""
    command: Command
    wire: str
    """What is sent: the line without its comment and outer spaces."""


@dataclass
class Script:
    """A parsed command file: its command lines and every line that did not parse."""

    name: str
    lines: list[ScriptLine] = field(default_factory=list)
    problems: list[str] = field(default_factory=list)
    """``name:line: error: ...`` for each line the parser rejected."""
    robot: str | None = None
    """The robot the file is written for: its ``# robot: NAME`` line, if it has one."""

    def problem(self, number: int, message: object) -> str:
        return f"{self.name}:{number}: error: {message}"


def load_script(path: Path, name: str | None = None) -> Script:
    """Read and parse a command file (comments and blank lines are dropped).

    The first ``# robot: NAME`` line among the comments that open the file (before
    its first command) names the robot it is written for (``Script.robot``).

    Args:
        path: The file.
        name: How messages name it (default: ``path`` as given).

    Raises:
        OSError: the file cannot be read.
    """
    script = Script(str(path) if name is None else name)
    text = path.read_bytes().decode("utf-8-sig", "replace")
    closed_at: ScriptLine | None = None
    for number, raw in enumerate(text.split("\n"), start=1):
        raw = raw.rstrip("\r")
        try:
            command = parse_line(raw)
        except C2rvizError as exc:
            script.problems.append(script.problem(number, exc))
            continue
        if command is None:
            header = _ROBOT_HEADER.fullmatch(raw.strip())
            if header and script.robot is None and not script.lines and not script.problems:
                script.robot = header.group(1)
            continue
        if closed_at is not None:
            verb = closed_at.wire.split()[0]
            script.problems.append(
                script.problem(
                    number,
                    f"line {closed_at.number} ({verb!r}) closes the connection, "
                    "so this line would never run",
                )
            )
        line = ScriptLine(number, raw, command, raw.split("#", 1)[0].strip())
        if isinstance(command, (Bye, Quit)) and closed_at is None:
            closed_at = line
        script.lines.append(line)
    return script


def check_robot(script: Script, robot: str, joint_names: Sequence[str]) -> list[str]:
    """Problems with ``joints`` counts and ``move`` indices for this robot's chain."""
    n = len(joint_names)
    problems = []
    for line in script.lines:
        command = line.command
        if isinstance(command, Joints) and len(command.values) != n:
            problems.append(script.problem(line.number, JointCountError(n, len(command.values))))
        elif isinstance(command, Move):
            bad = [i for i in command.indices if i >= n]
            if bad:
                problems.append(script.problem(line.number, JointIndexError(bad[0], robot, n)))
    return problems


def robot_mismatch(script: Script, robot: str, joint_names: Sequence[str]) -> str | None:
    """What to say when ``script`` declares another robot than the server's, else None."""
    if script.robot is None or script.robot == robot:
        return None
    return (
        f"{script.name} is written for robot {script.robot} (its '# robot:' line), "
        f"but the server runs {robot} ({len(joint_names)} joints)"
    )


def waits_for_the_arm(command: Command, motion: str) -> bool:
    """Whether ``command``'s reply waits for the arm, in motion mode ``motion``:
    a move with ``motion on`` (the reply comes on arrival), ``wait`` and ``stop``
    (at rest)."""
    if isinstance(command, (Wait, Stop)):
        return True
    return motion == "on" and isinstance(command, _MOVES)


def motion_after(script: Script, motion: str | None) -> str | None:
    """The motion mode after a play of ``script`` that began in ``motion``."""
    modes = [line.command.mode for line in script.lines if isinstance(line.command, MotionMode)]
    return next((mode for mode in reversed(modes) if mode is not None), motion)
