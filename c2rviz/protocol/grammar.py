"""The command language: one text line in, one frozen command out.

A pure parser: no sockets, no robot, no state. ``parse_line`` knows the shape
of every command (how many numbers, which words) but not the robot, so joint
counts, index ranges and limits are checked later by the session. Numbers are
returned exactly as written, in the client's units; the session converts.

Every verb is one entry of ``registry.VERBS``, declared on its command class
with ``@verb`` in ``verbs/`` (which imports the pieces here; this module
declares no verb); its handler lives on the session side (``session.handlers``).

Grammar (see the README for the full table):

- verbs are case-insensitive; ``#`` starts a comment; blank lines are ``None``;
- spaces and tabs separate words; spaces around commas are allowed;
- numbers are ASCII decimals (``-1``, ``2.5``, ``.5``, ``1e-3``); ``nan``,
  ``inf``, hex, underscores and non-ASCII digits are rejected, and so is a
  value that overflows to infinity (``1e309``).

The sane ranges (the end of this module): every number the language takes that no robot
limit bounds has one.

A value a parser accepts must also work everywhere after it: a tool offset of
1e300 m, a marker at 1e308 m (past float32 in the page) or an ``lspeed`` of
1e-320 m/s (a line that takes forever) pass a finiteness check and break later. So
each kind of number has a range here, checked by the verbs' parsers, with an error
that names it (docs/limits.md lists them).
"""

from __future__ import annotations

import difflib
import itertools
import math
import re
from collections.abc import Sequence

from ..errors import BadArguments, LineError, UnknownCommand, shown
from .registry import LOOKUP, usage

MARKER_SHAPES = ("sphere", "cube", "arrow", "cylinder")


class ForeignProtocol(LineError):
    """A line that is plainly another protocol (an HTTP request) hitting our port."""

    def __init__(self) -> None:
        super().__init__(
            "this is the c2rviz command port (one text command per line), not HTTP; "
            "open the viewer's address in a browser instead"
        )


# The grammar's pieces, shared by every verb's parser.

# Unambiguous (digits, then an optional fraction): a regex that could split a run of digits
# two ways backtracks quadratically, and one 8 KiB line held the event loop for 3 s.
_NUMBER = r"[+-]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?"
_NUMBER_RE = re.compile(_NUMBER)
_NUMBER_CHARS_RE = re.compile(r"[0-9.,eE+-]*")
_INDEX_RE = re.compile(r"[0-9]+")
_INDEX_LIST_RE = re.compile(r"[0-9]+(?:,[0-9]+)*")
_AROUND_COMMA_RE = re.compile(r"[ \t]*,[ \t]*")
# An HTTP request line (a method word, any case, then whitespace and "/"; or anything
# ending in " HTTP/1.1": HTTP/0.9's "GET /", "OPTIONS *", "CONNECT host:443 HTTP/1.1"),
# or one of the headers every HTTP client sends. Only these: a typo such as "where:"
# stays an unknown command, not a disconnect. Tried on the stripped line, and only when
# its first word is no verb.
_HTTP_RE = re.compile(
    r"(?i:get|post|put|delete|head|options|patch|connect|trace)\s+/.*"
    r"|.*\sHTTP/[0-9]\.[0-9]"
    r"|(?i:host|user-agent|accept|accept-encoding|accept-language|connection|content-length"
    r"|content-type|cookie|upgrade|origin|referer|sec-websocket-key):.*"
)
_MAX_INDEX_DIGITS = 9


def numbers(verb: str, text: str) -> tuple[float, ...]:
    """Parse a comma list of ASCII decimals; reject malformed and non-finite values."""
    values = None
    if _NUMBER_CHARS_RE.fullmatch(text) is not None:
        # Spelled with these characters alone, a value float() accepts is one _NUMBER
        # matches and back (no nan, inf, underscore or space can be written with them;
        # tests/test_parser.py tries every string of up to 6 of them), so float() does
        # the checking: 3x cheaper than the list regex on a stream of `joints` lines.
        try:
            values = tuple(map(float, text.split(",")))
        except ValueError:
            values = None
    if values is None:
        for item in text.split(","):
            if _NUMBER_RE.fullmatch(item) is None:
                problem = "empty value in list" if not item else f"bad number {shown(item)}"
                raise BadArguments(verb, problem, usage(verb))
        values = tuple(map(float, text.split(",")))
    # A sum is finite only if every value is (none is nan): one C call in the usual case.
    if not math.isfinite(sum(values)) and not all(map(math.isfinite, values)):
        big = next(item for item in text.split(",") if not math.isfinite(float(item)))
        raise BadArguments(verb, f"value {shown(big)} is not a finite number", usage(verb))
    return values


def numbers_batch(texts: Sequence[str], n: int) -> list[float] | None:
    """The values of several comma lists of exactly ``n`` decimals each (each may end in
    the ``\r`` of a CRLF line), read in one go: the hot path of a controller streaming
    ``joints`` lines. None when any list is not plainly that (its line is then parsed
    alone, by ``numbers``, which says what is wrong)."""
    joined = ",".join(texts)
    if "\r" in joined:
        joined = ",".join([t.removesuffix("\r") for t in texts])
    if _NUMBER_CHARS_RE.fullmatch(joined) is None:
        return None
    if list(map(str.count, texts, itertools.repeat(","))).count(n - 1) != len(texts):
        return None
    try:
        return list(map(float, joined.split(",")))  # as ``numbers``: float() judges them
    except ValueError:
        return None  # an empty or malformed value: its line says which


def indices(verb: str, text: str) -> tuple[int, ...]:
    """Parse a comma list of joint indices (ASCII digits, no sign)."""
    if _INDEX_LIST_RE.fullmatch(text) is None:
        for item in text.split(","):
            if _INDEX_RE.fullmatch(item) is None:
                problem = "empty index in list" if not item else f"bad joint index {shown(item)}"
                raise BadArguments(verb, problem, usage(verb))
    items = text.split(",")
    for item in items:
        if len(item) > _MAX_INDEX_DIGITS:
            raise BadArguments(verb, f"joint index {shown(item, 12)} is too large", usage(verb))
    return tuple(map(int, items))


def count(verb: str, values: tuple[float, ...], needed: int) -> tuple[float, ...]:
    """``values`` if there are ``needed`` of them, else ``BadArguments``."""
    if len(values) != needed:
        raise BadArguments(verb, f"needs {needed} values, got {len(values)}", usage(verb))
    return values


def one_word(verb: str, words: list[str]) -> str:
    """The single argument of ``verb``, else ``BadArguments``."""
    if len(words) != 1:
        problem = "needs an argument" if not words else f"takes 1 argument, got {len(words)}"
        if len(words) > 1 and all(_NUMBER_RE.fullmatch(word) for word in words):
            problem += " (separate values with commas: 1,2,3)"
        raise BadArguments(verb, problem, usage(verb))
    return words[0]


def numbers_arg(verb: str, words: list[str], needed: int) -> tuple[float, ...]:
    """The single argument of ``verb`` as exactly ``needed`` numbers."""
    return count(verb, numbers(verb, one_word(verb, words)), needed)


Command = object
"""Any command: an instance of a class registered with ``@verb``."""


def _clean(line: str) -> str:
    """Return ``line`` with tabs as spaces, or raise for any other control or non-ASCII."""
    line = line.replace("\t", " ")
    if line.isascii() and line.isprintable():
        return line
    for column, char in enumerate(line, start=1):
        if not (char.isascii() and char.isprintable()):
            raise LineError(
                f"character {ascii(char)} at column {column} is not allowed: "
                "commands are plain ASCII text"
            )
    return line  # pragma: no cover - the loop always finds the character


def parse_line(line: str) -> object | None:
    """Parse one line of the command language.

    Args:
        line: One line, with or without its trailing ``\\n`` / ``\\r\\n``.

    Returns:
        The command, or None for a blank or comment-only line.

    Raises:
        C2rvizError: ``UnknownCommand``, ``BadArguments``, ``LineError`` (or its
            ``ForeignProtocol``), each with a message for the user.
    """
    if "#" in line:
        line = line[: line.index("#")]
    line = line.rstrip("\r\n")
    if not (line.isascii() and line.isprintable()):
        line = _clean(line)
    words = line.split()
    if not words:
        return None
    entry = LOOKUP.get(words[0].lower())
    if entry is None:
        if _HTTP_RE.fullmatch(line.strip()):
            raise ForeignProtocol()
        typed = words[0].lower()
        close = tuple(difflib.get_close_matches(typed, LOOKUP, n=2, cutoff=0.75))
        raise UnknownCommand(words[0], close if len(typed) <= 40 else ())
    args = words[1:]
    if len(args) > 1 and "," in line:
        args = _AROUND_COMMA_RE.sub(",", " ".join(args)).split()
    return entry.parse(entry.name, args)


POSITION_M = 1000.0
"""A position (a pose's x, y, z, a marker's, an object's) lies within this of the origin [m]."""
TOOL_M = 10.0
"""A tool offset's x, y, z lie within this of the end-effector link [m]."""
ANGLE_LIMIT = 1e6
"""A pose's roll, pitch, yaw lie within this, in the connection's unit."""
SIZE_M = (1e-6, 100.0)
"""An object's size (edge, radius, length) [m]."""
LSPEED_M_S = (0.001, 5.0)
"""``lspeed``: the tool's straight-line speed [m/s]."""


def check_pose(verb: str, values: Sequence[float], position_m: float = POSITION_M) -> None:
    """Refuse a pose (x, y, z[, roll, pitch, yaw]) outside the sane ranges."""
    for axis, value in zip("xyz", values[:3]):
        if abs(value) > position_m:
            raise BadArguments(
                verb,
                f"{axis} = {value:g} m is outside -{position_m:g}..{position_m:g} m",
                usage(verb),
            )
    for name, value in zip(("roll", "pitch", "yaw"), values[3:]):
        if abs(value) > ANGLE_LIMIT:
            raise BadArguments(
                verb,
                f"{name} = {value:g} is outside -{ANGLE_LIMIT:g}..{ANGLE_LIMIT:g}",
                usage(verb),
            )


def check_sizes(verb: str, values: Sequence[float]) -> None:
    """Refuse an object size outside ``SIZE_M``."""
    low, high = SIZE_M
    for value in values:
        if not low <= value <= high:
            raise BadArguments(
                verb, f"size {value:g} m is outside {low:g}..{high:g} m", usage(verb)
            )
