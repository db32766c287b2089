"""How fast does the CRCL door answer, beside the text port?

Usage: ``python benchmarks/crcl_bench.py [--quick]``.

The program runs as a subprocess (``python -m c2rviz --no-viewer``, the motoman,
both doors on free ports); this process is the clients, on plain sockets:

1. round trip, one client: a ``GetStatus`` sent, its whole ``CRCLStatus`` read
   (cut at ``</CRCLStatus>``), p50/p99 [ms]; beside it the text port's ``where``
   request/reply. Goal (issue 24): GetStatus p99 <= 2 ms.
2. 10 clients polling at 100 Hz (one asyncio loop, each client on its own 10 ms
   schedule): statuses (or text replies) per second received, and the round trip's
   p99 under that load [ms]; 1000/s is the most there is to ask.
3. the codec's own costs, per document (``crcl_codec_bench.py``): parse a MoveTo,
   write a full status, p50/p99 [us]. Goal: <= 200 us each.

Figures only: nothing here passes or fails. The machine is shared (2 cores here):
its load average is printed first.
"""

from __future__ import annotations

import argparse
import asyncio
import os
import re
import socket
import statistics
import subprocess
import sys
import time
from collections.abc import Sequence
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))  # this checkout's c2rviz
sys.path.insert(0, str(ROOT / "benchmarks"))

from crcl_codec_bench import FULL as FULL_STATUS  # noqa: E402
from crcl_codec_bench import GOAL_US, MOVE_TO, per_call_us  # noqa: E402
from report import machine  # noqa: E402

from c2rviz.transports.crcl import parse_command, write_status  # noqa: E402

GOAL_P99_MS = 2.0
END = b"</CRCLStatus>"
GET_STATUS = (
    b'<?xml version="1.0" encoding="UTF-8"?>\n<CRCLCommandInstance xmlns:xsi='
    b'"http://www.w3.org/2001/XMLSchema-instance">\n  <CRCLCommand xsi:type="GetStatusType">\n'
    b"    <CommandID>1</CommandID>\n  </CRCLCommand>\n</CRCLCommandInstance>\n"
)
CLIENTS, RATE_HZ = 10, 100.0


def percentile(values: Sequence[float], fraction: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(fraction * len(ordered)))]


def start_program() -> tuple[subprocess.Popen[str], int, int]:
    """``c2rviz`` on free ports; return it, its text port and its CRCL port."""
    popen = subprocess.Popen(
        [sys.executable, "-m", "c2rviz", "--no-viewer", "--port", "0", "--crcl-port", "0"],
        cwd=ROOT,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        env={**os.environ, "PYTHONUNBUFFERED": "1"},
    )
    assert popen.stdout is not None
    text = crcl = None
    while text is None or crcl is None:
        line = popen.stdout.readline()
        if not line:
            raise RuntimeError("c2rviz did not start")
        if found := re.search(r"commands on [\d.]+:(\d+)", line):
            text = int(found.group(1))
        if found := re.search(r"CRCL on [\d.]+:(\d+)", line):
            crcl = int(found.group(1))
    return popen, text, crcl


def connect(port: int) -> socket.socket:
    sock = socket.create_connection(("127.0.0.1", port))
    sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
    return sock


def round_trips(port: int, request: bytes, end: bytes, count: int) -> list[float]:
    """Each request's time to its whole answer [ms], one at a time on one socket."""
    sock = connect(port)
    buffer = b""
    times = []
    try:
        for _ in range(count):
            start = time.perf_counter()
            sock.sendall(request)
            while end not in buffer:
                buffer += sock.recv(65536)
            buffer = buffer[buffer.index(end) + len(end) :]
            times.append((time.perf_counter() - start) * 1e3)
    finally:
        sock.close()
    return times


async def poll(port: int, request: bytes, end: bytes, seconds: float) -> tuple[int, list[float]]:
    """``CLIENTS`` clients asking at ``RATE_HZ`` each for ``seconds``: answers, round trips."""
    answers: list[float] = []

    async def one() -> None:
        reader, writer = await asyncio.open_connection("127.0.0.1", port)
        loop = asyncio.get_running_loop()
        due = loop.time()
        stop = due + seconds
        buffer = b""
        while due < stop:
            start = time.perf_counter()
            writer.write(request)
            while end not in buffer:
                buffer += await reader.read(65536)
            buffer = buffer[buffer.index(end) + len(end) :]
            answers.append((time.perf_counter() - start) * 1e3)
            due += 1.0 / RATE_HZ
            await asyncio.sleep(max(due - loop.time(), 0.0))
        writer.close()

    began = time.perf_counter()
    await asyncio.gather(*(one() for _ in range(CLIENTS)))
    return int(len(answers) / (time.perf_counter() - began)), answers


def row(*cells: str) -> str:
    widths = (34, 12, 12, 12, 6)
    return "| " + " | ".join(c.ljust(w) for c, w in zip(cells, widths)) + " |"


def main(argv: Sequence[str] | None = None) -> int:
    """Print the table; returns 0 (the goals are reported, not enforced)."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer round trips, 1 s of polling")
    args = parser.parse_args(argv)
    count, seconds, calls = (300, 1.0, 300) if args.quick else (5000, 10.0, 20_000)
    print(machine())
    print(f"round trips: {count} one client; polling: {CLIENTS} clients x {RATE_HZ:.0f} Hz "
          f"for {seconds:g} s")  # fmt: skip
    print(row("row", "CRCL", "text port", "goal", "met"))
    print(row(*("-" * w for w in (34, 12, 12, 12, 6))))
    popen, text_port, crcl_port = start_program()
    try:
        round_trips(crcl_port, GET_STATUS, END, 50)  # warm both up
        round_trips(text_port, b"where\n", b"\n", 50)
        crcl = round_trips(crcl_port, GET_STATUS, END, count)
        text = round_trips(text_port, b"where\n", b"\n", count)
        p99 = percentile(crcl, 0.99)
        print(row("1 round trip p50 [ms]", f"{statistics.median(crcl):.3f}",
                  f"{statistics.median(text):.3f}", "", ""))  # fmt: skip
        print(row("1 round trip p99 [ms]", f"{p99:.3f}", f"{percentile(text, 0.99):.3f}",
                  f"<= {GOAL_P99_MS:g} ms", "yes" if p99 <= GOAL_P99_MS else "no"))  # fmt: skip
        crcl_rate, crcl_times = asyncio.run(poll(crcl_port, GET_STATUS, END, seconds))
        text_rate, text_times = asyncio.run(poll(text_port, b"where\n", b"\n", seconds))
        print(row("2 10 clients at 100 Hz [answers/s]", f"{crcl_rate}", f"{text_rate}",
                  f"{CLIENTS * RATE_HZ:.0f}", ""))  # fmt: skip
        print(row("2 round trip p99 under it [ms]", f"{percentile(crcl_times, 0.99):.3f}",
                  f"{percentile(text_times, 0.99):.3f}", "", ""))  # fmt: skip
    finally:
        popen.terminate()
        popen.wait(timeout=30)
        if popen.stdout is not None:
            popen.stdout.close()
    for label, call in (
        ("3 parse a MoveTo [us]", lambda: parse_command(MOVE_TO)),
        ("3 write a full status [us]", lambda: write_status(FULL_STATUS)),
    ):
        walls, cpus = per_call_us(call, calls)
        p99 = percentile(cpus, 0.99)
        print(row(label, f"{statistics.median(walls):.1f} / {p99:.1f}", "", f"<= {GOAL_US:.0f} us",
                  "yes" if p99 <= GOAL_US else "no"))  # fmt: skip
    print("(3: median wall / p99 CPU time per call; benchmarks/crcl_codec_bench.py has more)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
