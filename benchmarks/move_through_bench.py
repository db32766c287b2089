"""Does a long CRCL MoveThroughTo stall the other clients while it is planned?

Usage: ``python benchmarks/move_through_bench.py [--waypoints N ...]``.

The program runs as a subprocess (``python -m c2rviz --no-viewer``, the motoman, the
text port and the CRCL door on free ports). One CRCL client sends InitCanon, then a
MoveThroughTo of N waypoints (the tool down, a few millimetres apart: every waypoint
solved and every leg checked before the arm moves); meanwhile a bystander on the text
port asks ``where`` in a loop. Printed: how long the MoveThroughTo took to plan (until
the bystander sees the arm move) and the bystander's ``where`` round trip p50/p99/max
[ms] while it was planned, beside the goal (issue 35: p99 <= 5 ms). The MoveThroughTo is
then stopped (StopMotion).

Figures only: nothing here passes or fails. The machine is shared: its load average is
printed first.
"""

from __future__ import annotations

import argparse
import socket
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))  # this checkout's c2rviz
sys.path.insert(0, str(ROOT / "benchmarks"))

from crcl_bench import percentile, start_program  # noqa: E402
from report import machine  # noqa: E402

GOAL_P99_MS = 5.0
XSI = "http://www.w3.org/2001/XMLSchema-instance"


def document(kind: str, command_id: int, body: str = "") -> bytes:
    return (
        f'<?xml version="1.0" encoding="UTF-8"?>\n<CRCLCommandInstance xmlns:xsi="{XSI}">\n'
        f'  <CRCLCommand xsi:type="{kind}Type">\n    <CommandID>{command_id}</CommandID>\n'
        f"{body}\n  </CRCLCommand>\n</CRCLCommandInstance>\n"
    ).encode()


def through(command_id: int, count: int) -> bytes:
    """A MoveThroughTo of ``count`` waypoints near (0.5, 0, 0.8) m, the tool down."""
    poses = []
    for k in range(count):
        y = 0.002 * (k % 10)  # a few millimetres apart, to and fro
        poses.append(
            "    <Waypoint><Point><X>0.5</X><Y>"
            f"{y!r}</Y><Z>0.8</Z></Point><XAxis><I>1</I><J>0</J><K>0</K></XAxis>"
            "<ZAxis><I>0</I><J>0</J><K>-1</K></ZAxis></Waypoint>"
        )
    body = "    <MoveStraight>false</MoveStraight>\n" + "\n".join(poses)
    return document("MoveThroughTo", command_id, body + f"\n<NumPositions>{count}</NumPositions>")


def read_status(sock: socket.socket, buffer: bytearray) -> bytes:
    end = b"</CRCLStatus>"
    while end not in buffer:
        chunk = sock.recv(65536)
        if not chunk:
            raise EOFError("the CRCL door closed")
        buffer += chunk
    cut = buffer.index(end) + len(end)
    status = bytes(buffer[:cut])
    del buffer[:cut]
    return status


def one(text_port: int, crcl_port: int, count: int) -> None:
    crcl = socket.create_connection(("127.0.0.1", crcl_port), timeout=120)
    bystander = socket.create_connection(("127.0.0.1", text_port), timeout=120)
    replies = bystander.makefile("rb")
    buffer = bytearray()
    crcl.sendall(document("InitCanon", 1))
    while b"<CommandID>1</CommandID>" not in read_status(crcl, buffer):
        pass
    bystander.sendall(b"where\n")
    home = replies.readline()
    doc = through(2, count)
    sent = time.perf_counter()
    crcl.sendall(doc)
    rounds: list[float] = []
    while True:
        start = time.perf_counter()
        bystander.sendall(b"where\n")
        reply = replies.readline()
        rounds.append((time.perf_counter() - start) * 1e3)
        if reply != home:
            break
    planned_s = time.perf_counter() - sent
    crcl.sendall(document("StopMotion", 3, "    <StopCondition>Immediate</StopCondition>"))
    print(
        f"MoveThroughTo {count:5d} waypoints ({len(doc) / 1024:.0f} KiB): planned in "
        f"{planned_s:.2f} s; bystander where p50 {percentile(rounds, 0.5):.2f} ms, "
        f"p99 {percentile(rounds, 0.99):.2f} ms, max {max(rounds):.2f} ms over "
        f"{len(rounds)} asks (goal p99 <= {GOAL_P99_MS:g} ms)"
    )
    crcl.close()
    bystander.close()


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--waypoints", type=int, nargs="+", default=[300, 1000])
    args = parser.parse_args(argv)
    print(machine())
    for count in args.waypoints:
        popen, text_port, crcl_port = start_program()
        try:
            one(text_port, crcl_port, count)
        finally:
            popen.terminate()
            popen.wait(30)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
