"""Does one client's big document or frame stall the others? (issue 35, stalls 3 and 4)

Usage: ``python benchmarks/door_stalls_bench.py [--seconds S] [--quick|--smoke]
[--only crcl|rosbridge]`` (``--quick``: one second a row; ``--smoke``, the test suite's:
every row on the least work, a quarter of a second a row after a quarter of flooding).

The program runs as a subprocess (``python -m c2rviz --no-viewer``, the motoman, every
door on a free port). While flooders in other processes send big input, a bystander on
the text port asks ``where`` 100 times a second; its round trips' p50/p99 are printed
beside the goal (issue 35: p99 <= 5 ms), and beside the same bystander with no flood.

1. CRCL flood: 4 clients each send 1 MiB ``MoveThroughTo`` documents (7000 waypoints,
   refused before InitCanon, so the cost is the parse), back to back, reading their
   statuses.
2. rosbridge trajectory: 4 clients each send ``/joint_trajectory`` frames of 8000 points
   (about 1 MB), one after the other: refused at a joint name the arm lacks (the decode
   and the message's read, in the door's decoding process, which sends back only the
   trajectory's outline; the loop's cost is the frame's receipt and the refusal), then
   refused by the plan's limit check (its first point too far for the time given: the
   decode, the read, the reading taken back and the plan).

Figures only: nothing here passes or fails. The machine is shared: its load average
is printed first.
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
import os
import re
import socket
import subprocess
import sys
import time
from collections.abc import Callable, Sequence
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "benchmarks"))

from report import machine  # noqa: E402

GOAL_P99_MS = 5.0
FLOODERS = 4
XSI = "http://www.w3.org/2001/XMLSchema-instance"
WAYPOINT = (
    "<Waypoint><Point><X>0.5</X><Y>0.0</Y><Z>0.8</Z></Point>"
    "<XAxis><I>1</I><J>0</J><K>0</K></XAxis><ZAxis><I>0</I><J>0</J><K>-1</K></ZAxis></Waypoint>\n"
)


def crcl_document(waypoints: int = 7000) -> bytes:
    """A MoveThroughTo of ``waypoints`` waypoints, just under 1 MiB."""
    body = WAYPOINT * waypoints
    return (
        f'<?xml version="1.0" encoding="UTF-8"?>\n<CRCLCommandInstance xmlns:xsi="{XSI}">\n'
        f'<CRCLCommand xsi:type="MoveThroughToType"><CommandID>2</CommandID>\n'
        f"<MoveStraight>false</MoveStraight>\n{body}<NumPositions>{waypoints}</NumPositions>\n"
        "</CRCLCommand></CRCLCommandInstance>\n"
    ).encode()


def trajectory_frame(points: int = 8000, unknown_joint: bool = False) -> str:
    """A /joint_trajectory publish of ``points`` points (about 1 MB), far from the arm
    (refused by its plan's check), or naming a joint the arm lacks (refused before it)."""
    names = ["joint_s", "joint_l", "joint_e", "joint_u", "joint_r", "joint_b", "joint_t"]
    if unknown_joint:
        names[-1] = "joint_x"
    raw = [
        {
            "positions": [round(0.3 + i * 1e-4, 4)] * 7,
            "time_from_start": {"sec": i // 100, "nanosec": (i % 100) * 10_000_000},
        }
        for i in range(1, points + 1)
    ]
    msg = {"joint_names": names, "points": raw}
    return json.dumps({"op": "publish", "topic": "/joint_trajectory", "msg": msg})


def start_program() -> tuple[subprocess.Popen[str], int, int, int]:
    """``c2rviz`` on free ports; return it and its text, CRCL and rosbridge ports."""
    popen = subprocess.Popen(
        [sys.executable, "-m", "c2rviz", "--no-viewer", "--port", "0", "--crcl-port", "0",
         "--rosbridge-port", "0"],
        cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
        env={**os.environ, "PYTHONUNBUFFERED": "1"},
    )  # fmt: skip
    assert popen.stdout is not None
    found: dict[str, int] = {}
    patterns = {
        "text": r"commands on [\d.]+:(\d+)",
        "crcl": r"CRCL on [\d.]+:(\d+)",
        "ros": r"rosbridge at ws://[\d.]+:(\d+)",
    }
    while len(found) < 3:
        line = popen.stdout.readline()
        if not line:
            raise RuntimeError(f"c2rviz did not start (found {found})")
        for name, pattern in patterns.items():
            if match := re.search(pattern, line):
                found[name] = int(match.group(1))
    return popen, found["text"], found["crcl"], found["ros"]


def flood_crcl(port: int, seconds: float) -> None:
    doc = crcl_document()
    sock = socket.create_connection(("127.0.0.1", port))
    sock.settimeout(0.0)
    stop = time.monotonic() + seconds
    pending = b""
    while time.monotonic() < stop:
        if not pending:
            pending = doc
        try:
            sent = sock.send(pending)
            pending = pending[sent:]
        except BlockingIOError:
            time.sleep(0.001)
        try:
            while sock.recv(65536):
                pass
        except BlockingIOError:
            pass
    sock.close()


def flood_rosbridge(port: int, seconds: float, unknown_joint: bool = False) -> None:
    from websockets.sync.client import connect

    frame = trajectory_frame(unknown_joint=unknown_joint)
    with connect(f"ws://127.0.0.1:{port}/", max_size=None) as ws:
        stop = time.monotonic() + seconds
        while time.monotonic() < stop:
            ws.send(frame)
            ws.send(json.dumps({"op": "call_service", "id": "s", "service": "/c2rviz/command",
                                "args": {"command": "where"}}))  # fmt: skip
            while json.loads(ws.recv(timeout=60)).get("op") != "service_response":
                pass  # a status about the refused trajectory


def flood_rosbridge_names(port: int, seconds: float) -> None:
    flood_rosbridge(port, seconds, unknown_joint=True)


def bystander(port: int, seconds: float) -> list[float]:
    """``where`` at 100 Hz on the text port for ``seconds``: each round trip [ms]."""
    sock = socket.create_connection(("127.0.0.1", port))
    sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
    file = sock.makefile("rb")
    times = []
    due = time.monotonic()
    stop = due + seconds
    while due < stop:
        start = time.perf_counter()
        sock.sendall(b"where\n")
        file.readline()
        times.append((time.perf_counter() - start) * 1e3)
        due += 0.01
        time.sleep(max(0.0, due - time.monotonic()))
    sock.close()
    return times


def percentile(values: Sequence[float], fraction: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(fraction * len(ordered)))]


def measure(
    text_port: int, flood: Callable[[int, float], None] | None, port: int, s: float, lead: float
) -> str:
    """The bystander's figures over ``s`` seconds, the flood ``lead`` seconds under way first."""
    workers = [
        multiprocessing.Process(target=flood, args=(port, s + lead)) for _ in range(FLOODERS)
    ] if flood else []  # fmt: skip
    for worker in workers:
        worker.start()
    time.sleep(lead if workers else 0.0)  # the flood under way
    times = bystander(text_port, s)
    for worker in workers:
        worker.join(60)
        if worker.is_alive():
            worker.terminate()
    p50, p99 = percentile(times, 0.5), percentile(times, 0.99)
    worst = max(times)
    return f"p50 {p50:.2f} ms, p99 {p99:.2f} ms, max {worst:.1f} ms (goal p99 <= {GOAL_P99_MS:g})"


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=5.0)
    parser.add_argument("--quick", action="store_true", help="one second a row")
    parser.add_argument("--smoke", action="store_true", help="every row, the least work")
    parser.add_argument("--only", choices=("crcl", "rosbridge"))
    args = parser.parse_args(argv)
    if args.quick:
        args.seconds = 1.0
    lead = 1.0
    if args.smoke:
        args.seconds, lead = 0.25, 0.25
    print(machine())
    popen, text, crcl, ros = start_program()
    try:
        print(f"bystander, no flood:            {measure(text, None, 0, args.seconds, lead)}")
        if args.only in (None, "crcl"):
            result = measure(text, flood_crcl, crcl, args.seconds, lead)
            print(f"bystander, 4 x 1 MiB CRCL flood: {result}")
        if args.only in (None, "rosbridge"):
            result = measure(text, flood_rosbridge_names, ros, args.seconds, lead)
            print(f"bystander, 4 x 8000-point traj. refused at a joint name: {result}")
            result = measure(text, flood_rosbridge, ros, args.seconds, lead)
            print(f"bystander, 4 x 8000-point traj. refused by its check:    {result}")
    finally:
        popen.terminate()
        popen.wait(10)
    return 0


if __name__ == "__main__":
    sys.exit(main())
