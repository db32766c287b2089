"""The parts an ini puts in the world: ``[parts]`` (around the first robot) and
``[parts:NAME]`` (around robot NAME of a cell), one per line, in that robot's base frame::

    [parts]
    p1 = box 0.03,0.03,0.06  0.45,0,0.03,0,0,0  type=block  color=1,0.5,0   # m, deg
    ball = sphere 0.02  0.5,0.2,0.02,0,0,0

Shapes, sizes and options are the ``part`` verb's (docs/parts.md); each is checked
again when it is added (a part inside an object is an error that names it).
"""

from __future__ import annotations

from pathlib import Path

import pinocchio as pin

from ..errors import ConfigError
from .robot_options import ini_entries, ini_numbers, pose_from

__all__ = ["IniPart", "ini_parts"]

IniPart = tuple[str, str, list[float], pin.SE3, "str | None", "tuple[float, ...] | None"]
"""name, shape, size, placement in the base frame, type, rgba (None: the default)."""


def ini_parts(ini: Path, robot: str, first: bool) -> list[IniPart]:
    """The parts the ini places around ``robot`` (``[parts]`` too when it is the first)."""
    found: list[IniPart] = []
    for where, name, text in ini_entries(ini, "parts", robot, first):
        words = text.split()
        if len(words) < 3:
            raise ConfigError(f"{where} = {text!r} needs a shape, a size and a pose")
        kind: str | None = None
        rgba: tuple[float, ...] | None = None
        for word in words[3:]:
            key, _, value = word.partition("=")
            if key == "type" and value:
                kind = value
            elif key in ("color", "colour") and value:
                rgba = (*ini_numbers(where, value), 1.0)
            else:
                raise ConfigError(f"{where}: {word!r} is not type=TYPE or color=r,g,b")
        size = ini_numbers(where, words[1])
        found.append((name, words[0].lower(), size, pose_from(where, words[2]), kind, rgba))
    return found
