"""Take docs/cameras.png: the live page with a table, parts, a wall, and two logical
cameras' frustums (one looking down on the table, one from the side, the wall hiding
a part from it), from the real program in headless Chromium.

Usage: ``python scripts/cameras_screenshot.py [--out DIR]`` (under a minute).
"""

from __future__ import annotations

import sys
from collections.abc import Sequence
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from page_screenshot import scene_picture  # noqa: E402

SCENE = [
    "degrees",
    "object table box 0.4,0.6,0.05 0.45,0,0.154,0,0,0",
    "object wall box 0.02,0.3,0.25 0.75,-0.1,0.3,0,0,0",
    "part p1 box 0.03,0.03,0.06 0.45,0,0.209,0,0,0 type=block color=0.9,0.5,0.1",
    "part p2 cylinder 0.02,0.06 0.55,-0.15,0.209,0,0,0 type=can color=0.8,0.2,0.2",
    "part ball sphere 0.025 0.4,0.2,0.204 color=0.9,0.9,0.2",
    "camera top 0.45,0,0.9,0,90,0 60,45,0.8",
    "camera side 1.1,-0.1,0.3,0,0,180 50,40,0.9",
    "joints 0,0,0,0,-60,0",
]


def main(argv: Sequence[str] | None = None) -> int:
    return scene_picture("cameras.png", SCENE, argv)


if __name__ == "__main__":
    sys.exit(main())
