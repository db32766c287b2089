"""A command file, checked in one pass with the server's own parser, then read again to play.

``load_script`` reads the file once, line by line, parsing each with
``c2rviz.protocol.parse_line``: every line that does not parse is listed
(``file:40: error: ...``; the first ``MAX_PROBLEMS``, then a count), while the robot is
still where it was. It keeps only a summary (the command count, the joint counts of
``joints`` lines, the highest ``move`` index, the ``# robot:`` header, the last
``motion`` mode), so a 59 MB recording costs a few kilobytes. ``check_robot`` then
checks that summary against the server's robot; ``Script.stream()`` reads the file
again, one line at a time, for playing. ``waits_for_the_arm`` and ``motion_after``
say which lines are answered on arrival. No sockets, nothing printed.
"""

from __future__ import annotations

import re
from collections.abc import Generator, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import C2rvizError, JointCountError, JointIndexError
from ..protocol.grammar import Command, parse_line
from ..protocol.verbs.arm import MotionMode, MoveL, MoveTo, Stop, Wait
from ..protocol.verbs.seed import Bye, Clear, Home, Joints, Move, Quit, Rand

_MOVES = (Joints, Move, Home, Rand, Clear, MoveTo, MoveL)
"""Commands whose reply comes on arrival with ``motion on``."""
MAX_PROBLEMS = 100
"""Problems a check lists; past it they are counted."""
MAX_LINE_BYTES = 1 << 20
"""Longest line a command file may have [bytes] (the server takes 8 KiB by default)."""

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
    """A checked command file: what a play needs to know before the first line is sent.

    Attributes:
        name: How messages name it.
        path: The file (``lines()`` reads it again).
        count: Its command lines.
        problems: ``name:line: error: ...`` for the first ``MAX_PROBLEMS`` lines that do
            not parse (or would never run); ``more_problems`` counts the rest.
        robot: The robot the file is written for: its ``# robot: NAME`` line, if any.
        joint_counts: For each number of values ``joints`` lines have, the line numbers
            having it (the first ``MAX_PROBLEMS``) and how many lines in all.
        move_indices: For each highest joint index of ``move`` lines, the same.
        closes: The line number and verb of the first ``bye`` or ``quit`` (None: none).
        last_mode: The last ``motion MODE`` line's mode (None: none).
    """

    name: str
    path: Path | None = None
    count: int = 0
    problems: list[str] = field(default_factory=list)
    more_problems: int = 0
    robot: str | None = None
    joint_counts: dict[int, tuple[list[int], int]] = field(default_factory=dict)
    move_indices: dict[int, tuple[list[int], int]] = field(default_factory=dict)
    closes: tuple[int, str] | None = None
    last_mode: str | None = None

    def problem(self, number: int, message: object) -> str:
        return f"{self.name}:{number}: error: {message}"

    def add_problem(self, number: int, message: object) -> None:
        if len(self.problems) < MAX_PROBLEMS:
            self.problems.append(self.problem(number, message))
        else:
            self.more_problems += 1

    def all_problems(self) -> list[str]:
        """The problems listed, and a line counting the rest."""
        more = [f"{self.name}: ... and {self.more_problems} more"] if self.more_problems else []
        return [*self.problems, *more]

    @property
    def lines(self) -> list[ScriptLine]:
        """Every command line, read into a list: for a short file (a player streams them)."""
        return list(self.stream())

    def stream(self) -> Generator[ScriptLine, None, None]:
        """The command lines, read from the file again one by one (for playing).

        Raises:
            OSError: the file cannot be read any more.
            C2rvizError: a line no longer parses (the file changed since it was checked).
        """
        if self.path is None:
            return
        for number, raw in _numbered_lines(self.path):
            if isinstance(raw, int):
                raise C2rvizError(self.problem(number, "the file changed since it was checked"))
            try:
                command = parse_line(raw)
            except C2rvizError as exc:
                raise C2rvizError(
                    self.problem(number, f"{exc} (the file changed since it was checked)")
                ) from None
            if command is not None:
                yield ScriptLine(number, raw, command, raw.split("#", 1)[0].strip())


def _numbered_lines(path: Path) -> Iterator[tuple[int, str | int]]:
    """Each line of ``path`` (text without its line end), numbered from 1; a line over
    ``MAX_LINE_BYTES`` comes as its length instead, and is skipped."""
    with path.open("rb") as file:
        number = 0
        while True:
            raw = file.readline(MAX_LINE_BYTES + 1)
            if not raw:
                return
            number += 1
            if len(raw) > MAX_LINE_BYTES and not raw.endswith(b"\n"):
                length = len(raw)
                while raw and not raw.endswith(b"\n"):  # skip the rest of it
                    raw = file.readline(MAX_LINE_BYTES)
                    length += len(raw)
                yield number, length
                continue
            text = raw.decode("utf-8", "replace").rstrip("\n").rstrip("\r")
            yield number, text.removeprefix("\ufeff") if number == 1 else text


def _note(table: dict[int, tuple[list[int], int]], key: int, number: int) -> None:
    numbers, total = table.get(key, ([], 0))
    if len(numbers) < MAX_PROBLEMS:
        numbers.append(number)
    table[key] = (numbers, total + 1)


def load_script(path: Path, name: str | None = None) -> Script:
    """Check a command file in one pass (comments and blank lines are skipped).

    The first ``# robot: NAME`` line among the comments that open the file (before
    its first command) names the robot it is written for (``Script.robot``).

    Args:
        path: The file.
        name: How messages name it (default: ``path`` as given).

    Raises:
        OSError: the file cannot be read.
    """
    script = Script(str(path) if name is None else name, path)
    for number, raw in _numbered_lines(path):
        if isinstance(raw, int):
            script.add_problem(number, f"line of {raw} bytes is over {MAX_LINE_BYTES}")
            continue
        try:
            command = parse_line(raw)
        except C2rvizError as exc:
            script.add_problem(number, exc)
            continue
        if command is None:
            header = _ROBOT_HEADER.fullmatch(raw.strip())
            if header and script.robot is None and not script.count and not script.problems:
                script.robot = header.group(1)
            continue
        if script.closes is not None:
            closed_at, verb = script.closes
            script.add_problem(
                number,
                f"line {closed_at} ({verb!r}) closes the connection, so this line would never run",
            )
        script.count += 1
        if isinstance(command, (Bye, Quit)) and script.closes is None:
            script.closes = (number, raw.split()[0])
        elif isinstance(command, Joints):
            _note(script.joint_counts, len(command.values), number)
        elif isinstance(command, Move):
            _note(script.move_indices, max(command.indices), number)
        elif isinstance(command, MotionMode) and command.mode is not None:
            script.last_mode = command.mode
    return script


def check_robot(script: Script, robot: str, joint_names: Sequence[str]) -> list[str]:
    """Problems with ``joints`` counts and ``move`` indices for this robot's chain (every
    offending line, up to ``MAX_PROBLEMS``, then a count)."""
    n = len(joint_names)
    found: list[tuple[int, str]] = []
    more = 0
    for count, (numbers, total) in script.joint_counts.items():
        if count != n:
            found += [(line, str(JointCountError(n, count))) for line in numbers]
            more += total - len(numbers)
    for index, (numbers, total) in script.move_indices.items():
        if index >= n:
            found += [(line, str(JointIndexError(index, robot, n))) for line in numbers]
            more += total - len(numbers)
    found.sort()
    more += max(0, len(found) - MAX_PROBLEMS)
    problems = [script.problem(line, message) for line, message in found[:MAX_PROBLEMS]]
    return problems + ([f"{script.name}: ... and {more} more"] if more else [])


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
    return script.last_mode or motion
