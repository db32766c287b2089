"""The processes under test: launch them, pin them, read their CPU time and memory."""

from __future__ import annotations

import contextlib
import os
import re
import signal
import socket
import subprocess
import sys
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

__all__ = ["HOST", "ROOT", "Launched", "launch_ceiling", "launch_ours", "pin_cpus"]

ROOT = Path(__file__).resolve().parent.parent
HOST = "127.0.0.1"


@dataclass
class Launched:
    """A server process, its addresses and when they came up."""

    popen: subprocess.Popen[str]
    launched_at: float
    port: int | None = None
    url: str | None = None
    port_open_s: float | None = None
    viewer_s: float | None = None
    output: list[str] = field(default_factory=list)
    _ready: threading.Event = field(default_factory=threading.Event)

    @property
    def address(self) -> tuple[str, int]:
        assert self.port is not None
        return HOST, self.port

    def cpu_s(self) -> float:
        """CPU time [s] used so far by every thread of the process (schedstat, ns)."""
        total = 0
        for task in Path(f"/proc/{self.popen.pid}/task").iterdir():
            with contextlib.suppress(FileNotFoundError, ProcessLookupError):  # a thread ended
                total += int((task / "schedstat").read_text().split()[0])
        return total / 1e9

    def rss_mb(self) -> float:
        """Resident memory [MB] (VmRSS)."""
        status = Path(f"/proc/{self.popen.pid}/status").read_text()
        kib = int(re.search(r"VmRSS:\s+(\d+)", status).group(1))  # type: ignore[union-attr]
        return kib / 1024

    def stop(self) -> None:
        if self.popen.poll() is None:
            self.popen.send_signal(signal.SIGTERM)
            try:
                self.popen.wait(timeout=10)
            except subprocess.TimeoutExpired:
                self.popen.kill()
                self.popen.wait(timeout=10)


class Line:
    """One blocking TCP client of the text port: a line out, a line back (the benchmarks'
    own, so each row measures the socket and not a client library)."""

    def __init__(self, address: tuple[str, int]) -> None:
        self.sock = socket.create_connection(address, timeout=120)
        self.sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        self.file = self.sock.makefile("rb")

    def send(self, line: str) -> None:
        self.sock.sendall(line.encode() + b"\n")

    def read(self) -> str:
        return self.file.readline().decode().rstrip("\n")

    def ask(self, line: str) -> str:
        self.send(line)
        return self.read()

    def ok(self, line: str) -> str:
        reply = self.ask(line)
        if not reply.startswith("ok"):
            raise RuntimeError(f"{line!r}: {reply!r}")
        return reply

    def timed(self, line: str) -> float:
        """The round trip of ``line`` [ms] (its reply must be ``ok...``)."""
        began = time.perf_counter()
        self.ok(line)
        return (time.perf_counter() - began) * 1e3

    def close(self) -> None:
        self.file.close()
        self.sock.close()


def free_port() -> int:
    with socket.socket() as sock:
        sock.bind((HOST, 0))
        return sock.getsockname()[1]


# CPUs for the servers and for the clients (this process); None: wherever the OS likes.
SERVER_CPUS: set[int] | None = None
CLIENT_CPUS: set[int] | None = None


def pin_cpus(enabled: bool) -> str:
    """Give the servers one CPU and the clients another, if there are two and we may.

    Unpinned, a request/reply round trip takes ~25 us when the scheduler happens to put
    client and server on one CPU and ~90 us when it wakes the other: medians jump between
    the two. Pinned, every run is the (realistic) two-CPU case.
    """
    global SERVER_CPUS, CLIENT_CPUS
    cpus = sorted(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else []
    if not enabled or len(cpus) < 2:
        return "not pinned"
    try:
        os.sched_setaffinity(0, set(cpus[:-1]))
    except OSError as exc:  # a container may forbid it: measure unpinned
        return f"not pinned ({exc.strerror})"
    SERVER_CPUS, CLIENT_CPUS = {cpus[-1]}, set(cpus[:-1])
    return f"servers on CPU {cpus[-1]}, clients on CPU {','.join(map(str, cpus[:-1]))}"


def launch(argv: list[str], viewer: bool, timeout_s: float = 60.0) -> Launched:
    """Start ``argv``; return once it prints its command port (and viewer URL)."""
    started = time.perf_counter()
    popen = subprocess.Popen(
        argv,
        cwd=ROOT,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        env={**os.environ, "PYTHONUNBUFFERED": "1"},
    )
    if SERVER_CPUS is not None:  # before it starts any thread: they inherit it
        with contextlib.suppress(OSError):
            os.sched_setaffinity(popen.pid, SERVER_CPUS)
    proc = Launched(popen, started)

    def read() -> None:
        assert popen.stdout is not None
        for line in popen.stdout:
            now = time.perf_counter()
            proc.output.append(line)
            if (m := re.search(r"commands on [\d.]+:(\d+)", line)) and proc.port is None:
                proc.port = int(m.group(1))
                proc.port_open_s = now - started
            if (m := re.search(r"viewer at (\S+)", line)) and proc.url is None:
                proc.url = m.group(1)
                proc.viewer_s = now - started
            if proc.port is not None and (proc.url is not None or not viewer):
                proc._ready.set()
        proc._ready.set()  # the process ended

    threading.Thread(target=read, daemon=True).start()
    if not proc._ready.wait(timeout_s) or proc.port is None:
        proc.stop()
        raise RuntimeError(f"{argv} did not start:\n{''.join(proc.output)}")
    return proc


def launch_ours(viewer: bool) -> Launched:
    argv = [sys.executable, "-m", "c2rviz", "--port", "0"]
    argv += ["--viser-port", str(free_port())] if viewer else ["--no-viewer"]
    return launch(argv, viewer)


def launch_ceiling(viewer: bool) -> Launched:
    argv = [sys.executable, str(ROOT / "benchmarks" / "ceiling.py"), "--port", "0"]
    argv += ["--viser-port", str(free_port())] if viewer else []
    return launch(argv, viewer)
