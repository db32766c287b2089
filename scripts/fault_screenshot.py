"""Take docs/faults-estop.png: the live page during an emergency stop (the banner atop the
robot's folder, the arm halted on its way over a table of parts, a logical camera's
frustum and what it sees), from the real program in headless Chromium.

Usage: ``python scripts/fault_screenshot.py [--out DIR]`` (under a minute). It starts
``python -m c2rviz`` on free ports, lays out the table, parts and camera, sends a move
with ``motion on``, stops it with ``fault estop`` on its way, and saves the page.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from cameras_screenshot import SCENE  # noqa: E402 (the script's neighbours)
from page_screenshot import ARGS, ROOT, Program  # noqa: E402

CELL = [line for line in SCENE if not line.startswith(("camera side", "joints"))]
"""The cameras' picture's table, wall and parts, and its camera looking down."""


def estop_page(browser: object, out: Path) -> None:
    program = Program(
        "--robot",
        "fanuc_lrmate200id",
        "--motion",
        "on",
        "--hz",
        "10",
        "--no-rosbridge",
        "--no-crcl",
    )
    try:
        page = browser.new_page(viewport={"width": 1400, "height": 900})  # type: ignore[attr-defined]
        page.goto(program.url + "/?fixedDpr=1")
        page.wait_for_function(
            "() => window.__viserSceneTree && Object.keys(window.__viserSceneTree.getState())"
            ".some((n) => n.endsWith('/link_6'))",
            timeout=120_000,
        )
        ask = program.ask
        for line in (*CELL, "speed 30", "fault after 1.5 estop"):
            ask(line)
        print(ask("j 0,40,-20,0,-60,0"))  # cut short: error: emergency stop since t=...
        print(ask("camera top"))
        print(ask("faults"))
        page.wait_for_function(
            "() => document.body.innerText.includes('EMERGENCY STOP')", timeout=60_000
        )
        page.add_style_tag(content="[class*='Notification'] { display: none !important; }")
        page.wait_for_timeout(1500)
        page.screenshot(path=str(out / "faults-estop.png"))
        print(f"wrote {out / 'faults-estop.png'}")
    finally:
        program.stop()


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--out", type=Path, default=ROOT / "docs", help="where the picture goes")
    args = parser.parse_args(argv)
    from playwright.sync_api import sync_playwright

    with sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path="/usr/bin/chromium", args=ARGS)
        try:
            estop_page(browser, args.out)
        finally:
            browser.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
