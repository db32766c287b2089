"""Take docs/page.png (the live page: plots, timeline, ghost, readout) and
docs/page-recorded.png (a recorded page) from the real program in headless Chromium.

Usage: ``python scripts/page_screenshot.py [--out DIR]`` (about a minute). It starts
``python -m c2rviz`` on free ports, drives the arm from a TCP client (a few moves, a
``movel`` caught on its way with its ghost and path line, a refused guarded move in red),
scrolls the side panel to the robot's plots, and saves the picture; then records a short
run, opens its NAME.html from the file and saves that too.
"""

from __future__ import annotations

import argparse
import re
import socket
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Sequence
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking"]


class Program:
    """``python -m c2rviz`` on free ports, and one TCP client."""

    def __init__(self, *args: str) -> None:
        self.popen = subprocess.Popen(
            [sys.executable, "-m", "c2rviz", "--port", "0", "--viser-port", "0", *args],
            cwd=ROOT,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
        )
        port = url = None
        assert self.popen.stdout is not None
        while port is None or url is None:
            line = self.popen.stdout.readline()
            if not line:
                raise RuntimeError("c2rviz did not start")
            if m := re.search(r"commands on [\d.]+:(\d+)", line):
                port = int(m.group(1))
            if m := re.search(r"viewer at (\S+)", line):
                url = m.group(1)
        self.url = url
        self.address = ("127.0.0.1", port)
        self.sock = socket.create_connection(self.address, timeout=60)
        self.replies = self.sock.makefile("rb")

    def ask(self, line: str) -> str:
        self.sock.sendall(line.encode() + b"\n")
        return self.replies.readline().decode().strip()

    def stop(self) -> None:
        self.sock.close()
        self.popen.terminate()
        out, _ = self.popen.communicate(timeout=30)
        if "Traceback" in out:
            print(out[-3000:])


def again(program: Program, stop: threading.Event) -> None:
    """Send the refused move again every second until ``stop``."""
    with socket.create_connection(program.address, timeout=60) as sock, sock.makefile("rb") as r:
        sock.sendall(b"degrees\nguard on\n")
        r.readline(), r.readline()
        while not stop.wait(1.0):
            sock.sendall(b"j -90,60,0,0,0,0,0\n")
            r.readline()


def live_page(browser: object, out: Path, record_dir: Path) -> None:
    # --hz 10: software WebGL draws a page this tall slowly; fewer frames keep it current
    program = Program("--record-dir", str(record_dir), "--motion", "on", "--hz", "10")
    try:
        # tall enough for the whole panel down to the first chart
        page = browser.new_page(viewport={"width": 1400, "height": 1700})  # type: ignore[attr-defined]
        page.goto(program.url + "/?fixedDpr=1")
        page.wait_for_function(
            "() => window.__viserSceneTree && Object.keys(window.__viserSceneTree.getState())"
            ".some((n) => n.endsWith('/link_t'))",
            timeout=120_000,
        )
        ask = program.ask
        for line in ("record take", "degrees", "speed 60"):
            ask(line)
        for target in ("60,30,0,-40,0,50,0", "-50,45,20,-30,40,60,0", "10,35,0,-50,0,70,0"):
            ask(f"j {target}")  # the reply comes on arrival (--motion on)
            ask("mark")
        ask("object table box 0.2,0.2,0.2 0,-0.8,0.85,0,0,0")  # beside the arm, at -y
        ask("j 0,60,0,0,0,0,0")  # the arm held out along +x
        ask("record stop")
        x, y, z, *angles = (float(v) for v in ask("pose")[3:].split(","))
        for line in ("guard on", "lspeed 0.015", "motion follow"):
            ask(line)
        print(ask("movel " + ",".join(map(str, [x - 0.2, y + 0.3, z, *angles]))))  # 20 s
        page.wait_for_timeout(2500)
        print(ask("j -90,60,0,0,0,0,0"))  # refused: it would hit the table (shown in red)
        # Software WebGL draws a page this tall slowly: the screenshot takes seconds, longer
        # than a refused target shows. A second client tries again meanwhile.
        stop = threading.Event()
        retry = threading.Thread(target=again, args=(program, stop), daemon=True)
        retry.start()
        page.wait_for_timeout(1000)
        start = time.perf_counter()
        page.screenshot(path=str(out / "page.png"))
        stop.set()
        retry.join()
        print(f"(took {time.perf_counter() - start:.1f} s; the arm: {ask('status')})")
        print(f"wrote {out / 'page.png'}")
    finally:
        program.stop()


def recorded_page(browser: object, out: Path, record_dir: Path) -> None:
    page = browser.new_page(viewport={"width": 1400, "height": 900})  # type: ignore[attr-defined]
    page.goto((record_dir / "take.html").as_uri())
    page.wait_for_function(
        "() => window.__c2rvizPlayer && window.__c2rvizPlayer.state().ready", timeout=120_000
    )
    end = page.evaluate("window.__c2rvizPlayer.state().endS")
    page.wait_for_timeout(4000)  # the viewer fades the scene in
    page.evaluate(f"window.__c2rvizPlayer.seek({end * 0.45})")
    page.wait_for_timeout(1500)
    page.screenshot(path=str(out / "page-recorded.png"))
    print(f"wrote {out / 'page-recorded.png'}")


def scene_picture(name: str, scene: Sequence[str], argv: Sequence[str] | None) -> int:
    """docs/NAME (or ``--out DIR``/NAME): the fanuc's live page after ``scene``'s lines, as
    the parts' and cameras' scripts take them."""
    parser = argparse.ArgumentParser(description=f"Take docs/{name} from the real program.")
    parser.add_argument("--out", type=Path, default=ROOT / "docs", help="where the picture goes")
    args = parser.parse_args(argv)
    from playwright.sync_api import sync_playwright

    program = Program("--robot", "fanuc_lrmate200id", "--hz", "10", "--no-crcl", "--no-rosbridge")
    try:
        with sync_playwright() as pw:
            browser = pw.chromium.launch(executable_path="/usr/bin/chromium", args=ARGS)
            try:
                page = browser.new_page(viewport={"width": 1200, "height": 800})
                page.goto(program.url + "/?fixedDpr=1")
                page.wait_for_function(
                    "() => window.__viserSceneTree && Object.keys("
                    "window.__viserSceneTree.getState()).some((n) => n.endsWith('/link_6'))",
                    timeout=120_000,
                )
                for line in scene:
                    print(line, "->", program.ask(line))
                page.wait_for_timeout(4000)
                page.screenshot(path=str(args.out / name))
                print(f"wrote {args.out / name}")
            finally:
                browser.close()
    finally:
        program.stop()
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--out", type=Path, default=ROOT / "docs", help="where the pictures go")
    args = parser.parse_args(argv)
    from playwright.sync_api import sync_playwright

    with tempfile.TemporaryDirectory() as folder, sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path="/usr/bin/chromium", args=ARGS)
        try:
            live_page(browser, args.out, Path(folder))
            recorded_page(browser, args.out, Path(folder))
        finally:
            browser.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
