"""Testing a controller: what the typed client costs, and how fast virtual time runs.

1. Client call overhead: ``where`` round trips to a real server (``python -m c2rviz
   --no-viewer``), through a raw socket (``sendall`` and ``recv`` to the newline) and
   through ``c2rviz.Client.where()`` (arguments checked, the reply framed and read as
   floats); interleaved blocks, the best block's time per call of each (the call's own
   cost, least disturbed by the rest of the machine), and the client process's CPU time
   per call (median). Goal: Client <= 1.3x raw.
   The same for ``joints`` (7 values written and checked against the robot).
2. Virtual time: wall time per simulated minute under ``--clock virtual`` with 1 and 8
   robots moving all the time (each driven by a client of its own that sends the next
   ``joints`` move, ``motion on``, as the last arrives; a cell of 8 motomans 3 m apart),
   timed by one more client's ``sleep 60``, and the server's CPU time meanwhile (on a
   busy machine the wall time waits for the CPU; the CPU time does not). Goal: <= 1 s a
   simulated minute.

Run: ``python benchmarks/testing_bench.py`` (``--quick``: fewer calls, 10 simulated
seconds scaled to a minute; ``--smoke``: every row on the least work, the test suite's
run). Servers on one CPU, clients on the other (when there are two).
"""

from __future__ import annotations

import argparse
import re
import socket
import statistics
import sys
import tempfile
import threading
import time
from collections.abc import Callable
from pathlib import Path

from processes import ROOT, launch, pin_cpus
from report import machine

sys.path.insert(0, str(ROOT))  # this tree's c2rviz, not an installed one

from c2rviz import Client  # noqa: E402

__all__ = ["main"]

PORT = re.compile(r"commands on [\d.]+:(\d+)")
GOAL_RATIO = 1.3
GOAL_MINUTE_S = 1.0
JOINTS = [0.1, 0.2, 0.3, -0.4, 0.5, -0.6, 0.7]
MOVES = ([0.8, 0.4, 0.3, -0.6, 0.4, 0.6, 0.5], [-0.8, -0.4, -0.3, 0.6, -0.4, -0.6, -0.5])


def raw_calls(sock: socket.socket, line: bytes, count: int) -> float:
    """Per-call time [s] of ``count`` round trips of ``line`` over a raw socket."""
    start = time.perf_counter()
    for _ in range(count):
        sock.sendall(line)
        reply = sock.recv(4096)
        while not reply.endswith(b"\n"):
            reply += sock.recv(4096)
    return (time.perf_counter() - start) / count


def client_calls(call: Callable[[], object], count: int) -> float:
    start = time.perf_counter()
    for _ in range(count):
        call()
    return (time.perf_counter() - start) / count


def measure_overhead(blocks: int, per_block: int) -> list[tuple[str, str, float, str, str]]:
    server = launch([sys.executable, "-m", "c2rviz", "--no-viewer", "--port", "0"], False)
    rows = []
    try:
        host, port = server.address
        with socket.create_connection((host, port)) as sock, Client(host, port) as client:
            sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            client.names()
            joints = f"joints {','.join(map(repr, JOINTS))}\n".encode()
            for label, line, call in (
                ("where", b"where\n", client.where),
                ("joints", joints, lambda: client.joints(JOINTS)),
            ):
                raw, typed, raw_cpu, typed_cpu = [], [], [], []
                for _ in range(blocks):  # interleaved: both see the same machine
                    cpu = time.process_time()
                    raw.append(raw_calls(sock, line, per_block))
                    raw_cpu.append((time.process_time() - cpu) / per_block)
                    cpu = time.process_time()
                    typed.append(client_calls(call, per_block))
                    typed_cpu.append((time.process_time() - cpu) / per_block)
                # The best block of each: the cost of the call itself, least disturbed by
                # whatever else the machine runs.
                r, c = min(raw) * 1e6, min(typed) * 1e6
                rows.append((f"1 {label}: raw socket", "us/call", r, "", ""))
                rows.append((f"1 {label}: Client", "us/call", c, "", ""))
                cpu_r, cpu_c = statistics.median(raw_cpu) * 1e6, statistics.median(typed_cpu) * 1e6
                rows.append((f"1 {label}: client CPU, raw", "us/call", cpu_r, "", ""))
                rows.append((f"1 {label}: client CPU, Client", "us/call", cpu_c, "", ""))
                ratio = c / r
                goal = f"<= {GOAL_RATIO}x" if label == "where" else ""
                met = ("yes" if ratio <= GOAL_RATIO else "no") if goal else ""
                rows.append((f"1 {label}: Client/raw", "x", ratio, goal, met))
    finally:
        server.stop()
    return rows


def write_cell(folder: Path, count: int) -> Path:
    urdf = ROOT / "robots" / "motoman_sia20d" / "robot.urdf"
    names = [f"arm{i}" for i in range(count)]
    sections = [
        "[options]\nhost = 127.0.0.1\n",
        f"[motoman_sia20d]\nbase = base_link\neelink = link_t\nurdf = {urdf}\n",
        f"[cell:bench]\nrobots = {' '.join(names)}\n",
    ]
    for i, name in enumerate(names):
        sections.append(f"[{name}]\nrobot = motoman_sia20d\norigin = {3 * i},0,0,0,0,0\nport = 0\n")
    path = folder / "cell.ini"
    path.write_text("\n".join(sections))
    return path


def _ports(output: list[str], count: int) -> list[int]:
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline:
        found = [int(m.group(1)) for line in output if (m := PORT.search(line))]
        if len(found) >= count:
            return found[:count]
        time.sleep(0.01)
    raise RuntimeError("the cell did not open its ports:\n" + "".join(output))


def mover(port: int, done: threading.Event) -> None:
    with Client("127.0.0.1", port) as robot:
        robot.motion("on")
        robot.speed(100)
        k = 0
        while not done.is_set():
            robot.joints(MOVES[k % 2])  # returns on arrival
            k += 1


def measure_virtual(robots: int, simulated_s: float) -> tuple[float, float]:
    """Wall time and the server's CPU time [s] of ``simulated_s`` of virtual time with
    ``robots`` arms always moving."""
    with tempfile.TemporaryDirectory() as folder:
        argv = [sys.executable, "-m", "c2rviz", "--no-viewer", "--clock", "virtual"]
        if robots > 1:
            argv += ["--config", str(write_cell(Path(folder), robots)), "--cell", "bench"]
        argv += ["--port", "0"]
        server = launch(argv, False)
        try:
            ports = _ports(server.output, robots)
            done = threading.Event()
            threads = [
                threading.Thread(target=mover, args=(port, done), daemon=True) for port in ports
            ]
            with Client("127.0.0.1", ports[0]) as keeper:
                keeper.where()
                for thread in threads:
                    thread.start()
                time.sleep(1.0)  # every mover connected and moving
                start, cpu = time.perf_counter(), server.cpu_s()
                keeper.sleep(simulated_s)
                wall, cpu = time.perf_counter() - start, server.cpu_s() - cpu
                done.set()
            for thread in threads:  # the keeper gone, the last moves end (virtual time again)
                thread.join(timeout=60)
        finally:
            server.stop()
    return wall, cpu


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer calls, 10 s simulated")
    parser.add_argument("--smoke", action="store_true", help="every row, the least work")
    args = parser.parse_args(argv)
    # (blocks, calls a block, simulated seconds)
    blocks, per_block, simulated = (
        (2, 50, 2.0) if args.smoke else (6, 200, 10.0) if args.quick else (20, 1000, 60.0)
    )
    pinned = pin_cpus(True)
    print(machine())
    print(f"pinning: {pinned}")
    rows = measure_overhead(blocks, per_block)
    for robots in (1, 8):
        wall, cpu = measure_virtual(robots, simulated)
        per_minute = wall * 60.0 / simulated
        met = "yes" if per_minute <= GOAL_MINUTE_S else "no"
        label = f"2 virtual: {robots} robot{'s' if robots > 1 else ''} moving"
        rows.append((label, "s/sim min", per_minute, f"<= {GOAL_MINUTE_S:g} s", met))
        rows.append((f"{label}: server CPU", "s/sim min", cpu * 60.0 / simulated, "", ""))
    print("| row | unit | figure | goal | met |")
    print("|---|---|---|---|---|")
    for label, unit, value, goal, met in rows:
        print(f"| {label} | {unit} | {value:.3g} | {goal} | {met} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
