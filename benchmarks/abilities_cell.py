"""Abilities row 4: a three-robot cell (``--cell``): start-up and pipelined throughput.

A temporary ini holds the three bundled robots (absolute URDF paths) and
``[cell:three]`` with one member each, every port 0 (the program picks free
ones and its banner says which). Figures: launch -> the last robot's command
port open; pipelined ``joints`` throughput of one robot alone, then of each robot
while all three are driven at once (one pipelined client each, in threads of
this process).
"""

from __future__ import annotations

import re
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import loadgen
from line_clients import Figure
from processes import HOST, ROOT, Launched, free_port, launch

__all__ = ["CELL_ROBOTS", "cell_supported", "measure_cell"]

# Member name -> (robot section, base, eelink, chain joints).
CELL_ROBOTS = {
    "one": ("motoman_sia20d", "base_link", "link_t", 7),
    "two": ("fanuc_lrmate200id", "base_link", "link_6", 6),
    "three": ("kuka_lwr", "lwr_base_link", "lwr_7_link", 7),
}
_ORIGINS = ("0,0,0,0,0,0", "1.2,0,0,0,0,180", "0,1.2,0,0,0,-90")


def cell_supported() -> bool:
    """True if this tree's ``python -m c2rviz`` takes ``--cell``."""
    done = subprocess.run(
        [sys.executable, "-m", "c2rviz", "--help"], cwd=ROOT, capture_output=True, text=True
    )
    return "--cell" in done.stdout


def write_ini(folder: Path) -> Path:
    sections = ["[options]\nhost = 127.0.0.1\n"]
    for section, base, eelink, _ in CELL_ROBOTS.values():
        urdf = ROOT / "robots" / section / "robot.urdf"
        sections.append(f"[{section}]\nbase = {base}\neelink = {eelink}\nurdf = {urdf}\n")
    sections.append(f"[cell:trio]\nrobots = {' '.join(CELL_ROBOTS)}\n")
    for (name, (section, *_)), origin in zip(CELL_ROBOTS.items(), _ORIGINS):
        sections.append(f"[{name}]\nrobot = {section}\norigin = {origin}\nport = 0\n")
    path = folder / "cell.ini"
    path.write_text("\n".join(sections))
    return path


def _ports(proc: Launched, count: int, timeout_s: float = 60.0) -> dict[str, int]:
    """Each member's command port, from the banner (``NAME: commands on HOST:PORT``)."""
    deadline = time.perf_counter() + timeout_s
    while time.perf_counter() < deadline:
        found = {}
        for line in list(proc.output):
            if m := re.search(r"(\w+): commands on [\d.]+:(\d+)", line):
                found[m.group(1)] = int(m.group(2))
        if len(found) >= count:
            return found
        if proc.popen.poll() is not None:
            break
        time.sleep(0.002)
    raise RuntimeError(f"the cell did not open {count} ports:\n{''.join(proc.output)}")


def measure_cell(pipelined: int) -> dict[str, Figure]:
    """Launch the cell, time its start-up, drive its robots alone and all at once."""
    out: dict[str, Figure] = {}
    with tempfile.TemporaryDirectory() as folder:
        ini = write_ini(Path(folder))
        argv = [sys.executable, "-m", "c2rviz", "--config", str(ini), "--cell", "trio"]
        argv += ["--port", "0", "--viser-port", str(free_port())]
        proc = launch(argv, viewer=True)
        try:
            ports = _ports(proc, len(CELL_ROBOTS))  # polled every 2 ms
            out["cell_ports_open"] = Figure(time.perf_counter() - proc.launched_at)
            lines = {name: loadgen.joints_lines(n, 1000) for name, (*_, n) in CELL_ROBOTS.items()}
            repeat = max(1, pipelined // 1000)
            first = next(iter(CELL_ROBOTS))
            out["cell_alone"] = Figure(
                loadgen.pipelined((HOST, ports[first]), lines[first], repeat)
            )
            rates: dict[str, float] = {}

            def drive(name: str) -> None:
                rates[name] = loadgen.pipelined((HOST, ports[name]), lines[name], repeat)

            threads = [threading.Thread(target=drive, args=(name,)) for name in CELL_ROBOTS]
            for thread in threads:
                thread.start()
            for thread in threads:
                thread.join(timeout=600)
            for name, (section, *_) in CELL_ROBOTS.items():
                out[f"cell_busy_{section}"] = Figure(rates[name])
            out["cell_busy_sum"] = Figure(sum(rates.values()))
        finally:
            proc.stop()
    return out
