"""Markers: clear, mark, color/rgb, marker (the seed's own verbs)."""

from __future__ import annotations

from dataclasses import dataclass

from ...errors import BadArguments, shown
from ..grammar import MARKER_SHAPES, numbers_arg, one_word
from ..ranges import check_pose
from ..registry import usage, verb

__all__ = ["Clear", "Color", "Mark", "MarkerShape"]


@verb("clear", "", "home, and remove every marker")
@dataclass(frozen=True, slots=True)
class Clear:
    """Home the robot and remove every marker."""


@verb(
    "mark",
    "[world] [x,y,z,roll,pitch,yaw]",
    "drop a marker at that pose in the base frame (metres; angles in the connection's unit), "
    "or with `world` in the world (cell) frame; without a pose, at the end effector",
)
@dataclass(frozen=True, slots=True)
class Mark:
    """Drop a marker at ``pose`` (x, y, z [m], roll, pitch, yaw [client's units]).

    ``pose`` is None for a marker at the current end-effector pose; ``in_world``
    puts it in the world (cell) frame instead of the robot's base frame.
    """

    pose: tuple[float, float, float, float, float, float] | None
    in_world: bool = False

    @staticmethod
    def parse(verb: str, words: list[str]) -> Mark:
        in_world = bool(words) and words[0].lower() == "world"
        if in_world:
            words = words[1:]
            if not words:
                raise BadArguments(verb, "world needs a pose", usage(verb))
        if not words:
            return Mark(None)
        x, y, z, roll, pitch, yaw = numbers_arg(verb, words, 6)
        check_pose(verb, (x, y, z, roll, pitch, yaw))
        return Mark((x, y, z, roll, pitch, yaw), in_world)


@verb(
    "rgb",
    "r,g,b (0..255)",
    "the same, each channel 0..255",
    parse=lambda verb, words: Color.parse(verb, words, 255.0),
)
@verb(
    "color",
    "r,g,b (0..1)",
    "colour of this connection's next markers, each channel 0..1",
    parse=lambda verb, words: Color.parse(verb, words, 1.0),
)
@dataclass(frozen=True, slots=True)
class Color:
    """Colour of this connection's next markers, each channel 0..1."""

    rgb: tuple[float, float, float]

    @staticmethod
    def parse(verb: str, words: list[str], top: float) -> Color:
        r, g, b = numbers_arg(verb, words, 3)
        for channel in (r, g, b):
            if not 0.0 <= channel <= top:
                raise BadArguments(verb, f"channel {channel:g} is outside 0..{top:g}", usage(verb))
        return Color((r / top, g / top, b / top))


@verb(
    "marker",
    "|".join(MARKER_SHAPES),
    "shape of this connection's next markers (default a small red sphere)",
)
@dataclass(frozen=True, slots=True)
class MarkerShape:
    """Shape of this connection's next markers, one of ``MARKER_SHAPES``."""

    shape: str

    @staticmethod
    def parse(verb: str, words: list[str]) -> MarkerShape:
        shape = one_word(verb, words).lower()
        if shape not in MARKER_SHAPES:
            raise BadArguments(verb, f"unknown shape {shown(shape)}", usage(verb))
        return MarkerShape(shape)
