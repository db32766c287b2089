"""Abilities rows 2 and 3: Cartesian commands and collision guarding, over the socket.

Every time here is a request/reply round trip on 127.0.0.1 measured by the
client: it includes the round trip itself (~0.1 ms on this machine, see
``run.py`` row 2), nothing is subtracted.

Row 2 (per robot): ``ik`` of targets made by the server's own forward
kinematics (``rand`` then ``pose``), solved from a random arm configuration
(``rand`` before each) and from one near the target's (each joint within
0.2 rad, by ``j``); ``movel`` of 0.5 m lines (random direction, orientation
kept) from random configurations with ``motion off``, the lines that pass;
and a bystander's ``where`` round trips while another client sends ``ik``
in a loop.

Row 3: ``j`` round trips with ``guard off`` / ``on``, with no objects and with
ten small spheres far away (``object oK sphere 0.05 3,K,0``); the first
``guard on`` (which builds the collision model).
"""

from __future__ import annotations

import re
import threading
import time
from dataclasses import dataclass

import loadgen
import numpy as np
from line_clients import Bystander, Figure, LineClient, percentile, round_trips
from processes import Launched

__all__ = ["ArmPlan", "measure_cartesian", "measure_guard", "measure_ik_bystander"]

_RANGE = re.compile(r"([-+]?[\d.]+(?:e[-+]?\d+)?)\.\.([-+]?[\d.]+(?:e[-+]?\d+)?)")


@dataclass(frozen=True)
class ArmPlan:
    """How much of rows 2 and 3 one repetition does."""

    ik_targets: int = 100
    lines: int = 10
    line_m: float = 0.5
    bystander_s: float = 4.0
    guard_round_trips: int = 2000
    seed: int = 7


def _floats(text: str) -> list[float]:
    return [float(v) for v in text.split(",")]


def _csv(values: list[float] | np.ndarray) -> str:
    return ",".join(f"{v:.6f}" for v in values)


def _settle() -> None:
    time.sleep(0.015)  # let the viewer's send of the last move go out first


def _targets(client: LineClient, count: int) -> list[tuple[list[float], str]]:
    """``count`` (q, pose) pairs: the server's FK of random in-limit configurations."""
    out = []
    for _ in range(count):
        client.ok("rand")
        out.append((_floats(client.ok("where")), client.ok("pose")))
    return out


def measure_cartesian(proc: Launched, robot: str, plan: ArmPlan) -> dict[str, Figure]:
    """``ik`` (random and near seed) and ``movel`` round trips on one robot's server."""
    rng = np.random.default_rng(plan.seed)
    client = LineClient(proc.address)
    out: dict[str, Figure] = {}
    try:
        limits = [(float(a), float(b)) for a, b in _RANGE.findall(client.ok("limits"))]
        low, high = np.array(limits).T + [[1e-5], [-1e-5]]  # printed values are rounded
        targets = _targets(client, plan.ik_targets)
        for seed in ("rand", "near"):
            times, failed = [], 0
            for q, pose in targets:
                if seed == "rand":
                    client.ok("rand")
                else:
                    near = np.clip(np.array(q) + rng.uniform(-0.2, 0.2, len(q)), low, high)
                    client.ok("j " + _csv(near))
                _settle()
                reply, seconds = client.ask(f"ik {pose}")
                times.append(seconds)
                failed += not reply.startswith("ok")
            out[f"ik_{seed}_p50_{robot}"] = Figure(percentile(times, 50) * 1e3)
            out[f"ik_{seed}_p99_{robot}"] = Figure(percentile(times, 99) * 1e3)
            out[f"ik_{seed}_failed_{robot}"] = Figure(100.0 * failed / len(targets))
        times, refused = [], 0
        while len(times) < plan.lines and refused < 20 * plan.lines:
            client.ok("rand")
            start = _floats(client.ok("pose"))
            direction = rng.normal(size=3)
            end = np.array(start[:3]) + plan.line_m * direction / np.linalg.norm(direction)
            _settle()
            reply, seconds = client.ask("movel " + _csv([*end, *start[3:]]))
            if reply.startswith("ok"):
                times.append(seconds)
            else:
                refused += 1
        if times:
            out[f"movel_p50_{robot}"] = Figure(percentile(times, 50) * 1e3)
            out[f"movel_max_{robot}"] = Figure(max(times) * 1e3)
        out[f"movel_refused_{robot}"] = Figure(100.0 * refused / (refused + len(times)))
    finally:
        client.close()
    return out


def measure_ik_bystander(proc: Launched, plan: ArmPlan) -> dict[str, Figure]:
    """A bystander's ``where`` round trips at rest, then while another client loops ``ik``."""
    out: dict[str, Figure] = {}
    times, _ = Bystander(proc.address, plan.bystander_s, "where").result()
    out["ik_by_idle_p50"] = Figure(percentile(times, 50) * 1e6)
    out["ik_by_idle_p99"] = Figure(percentile(times, 99) * 1e6)
    client = LineClient(proc.address)
    targets = _targets(client, 20)
    stop = threading.Event()
    solved = [0]

    def loop() -> None:
        k = 0
        while not stop.is_set():
            client.ask(f"ik {targets[k % len(targets)][1]}")
            solved[0] += 1
            k += 1

    looper = threading.Thread(target=loop, daemon=True)
    looper.start()
    try:
        started = time.perf_counter()
        times, _ = Bystander(proc.address, plan.bystander_s, "where").result()
        elapsed = time.perf_counter() - started
    finally:
        stop.set()
        looper.join(timeout=60)
        client.close()
    out["ik_by_busy_p50"] = Figure(percentile(times, 50) * 1e6)
    out["ik_by_busy_p99"] = Figure(percentile(times, 99) * 1e6)
    out["ik_loop_rate"] = Figure(solved[0] / elapsed)
    return out


def measure_guard(proc: Launched, plan: ArmPlan) -> dict[str, Figure]:
    """``j`` round trips, guard off/on, 0/10 objects, on a fresh server (no model yet)."""
    lines = [line.decode().strip() for line in loadgen.joints_lines(7, 1000)]
    client = LineClient(proc.address)
    out: dict[str, Figure] = {}

    def rows(key: str) -> None:
        times, refused = round_trips(client, lines, plan.guard_round_trips)
        out[f"{key}_p50"] = Figure(percentile(times, 50) * 1e6)
        out[f"{key}_p99"] = Figure(percentile(times, 99) * 1e6)
        out[f"{key}_refused"] = Figure(100.0 * refused / len(times))

    try:
        rows("guard_off_0")
        reply, seconds = client.ask("guard on")
        if reply != "ok":
            raise RuntimeError(f"guard on: {reply!r}")
        out["guard_first"] = Figure(seconds * 1e3)
        rows("guard_on_0")
        for k in range(10):
            client.ok(f"object o{k} sphere 0.05 3,{k},0")
        rows("guard_on_10")
        client.ok("guard off")
        rows("guard_off_10")
    finally:
        client.close()
    return out
