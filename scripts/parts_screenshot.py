"""Take docs/parts.png: the live page with a table, parts, goals' outlines and a part held
by the fanuc's gripper, from the real program in headless Chromium.

Usage: ``python scripts/parts_screenshot.py [--out DIR]`` (under a minute).
"""

from __future__ import annotations

import sys
from collections.abc import Sequence
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from page_screenshot import scene_picture  # noqa: E402

SCENE = [
    "grip 1",
    "object table box 0.4,0.6,0.05 0.45,0,0.154,0,0,0",
    "object tray box 0.2,0.2,0.02 0.1,0.45,0.01,0,0,0",
    "part p1 box 0.03,0.03,0.17 0.4438,0,0.264,0,0,0 type=block color=0.9,0.5,0.1",
    "part p2 box 0.03,0.03,0.12 0.55,0.2,0.239,0,0,0 type=block color=0.2,0.5,0.9",
    "part p3 cylinder 0.02,0.06 0.35,-0.2,0.209,0,0,0 type=can color=0.8,0.2,0.2",
    "part ball sphere 0.025 0.55,-0.15,0.204 color=0.9,0.9,0.2",
    "goal p1 0.1,0.45,0.105,0,0,0",
    "goal p2 0.1,0.5,0.08,0,0,0",
    "goal type=can 0.05,0.4,0.05,0,0,0",
    "joints 0,0.3,-0.3,0,-0.9707963,0",
    "grip 0",
    "joints 0.6,0.1,-0.1,0,-1.3707963,0",
]


def main(argv: Sequence[str] | None = None) -> int:
    return scene_picture("parts.png", SCENE, argv)


if __name__ == "__main__":
    sys.exit(main())
