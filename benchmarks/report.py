"""The table: rows, targets, median and spread, ratio, and the machine line."""

from __future__ import annotations

import os
import platform
import re
import statistics
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

__all__ = ["ROWS", "Figures", "Row", "machine", "table"]

Figures = dict[str, float]


@dataclass(frozen=True)
class Row:
    key: str
    label: str
    unit: str
    fmt: str
    target: str
    check: Callable[[float, float | None], bool] | None = None
    """(ours, ratio) -> met."""
    viewer: bool = False


ROWS = [
    Row("pipelined", "1 pipelined, 1 client", "cmd/s", ",.0f", ">= 0.5x", lambda v, r: r >= 0.5),
    Row("cpu_per_cmd", "1 pipelined: server CPU", "us/cmd", ".2f", ""),
    Row("rr_p50", "2 request/reply p50", "us", ".0f", ""),
    Row("rr_p99", "2 request/reply p99", "us", ".0f", "<= 1.5x", lambda v, r: r <= 1.5),
    Row("many_rate", "3 50 clients", "cmd/s", ",.0f", ">= 0.6x", lambda v, r: r >= 0.6),
    Row("many_p99", "3 50 clients p99", "us", ".0f", ""),
    Row("frame_p50", "4 command->frame p50", "ms", ".2f", "<= 5 ms", lambda v, r: v <= 5, True),
    Row("frame_p99", "4 command->frame p99", "ms", ".2f", "<= 20 ms", lambda v, r: v <= 20, True),
    Row("flood_fps", "5 flood: viewer frames", "fps", ".0f", ">= 50", lambda v, r: v >= 50, True),
    Row("flood_rate", "5 flood: TCP meanwhile", "cmd/s", ",.0f", ">= 0.4x", lambda v, r: r >= 0.4),
    Row("port_open", "6 launch->port open", "s", ".3f", "<= 2 s", lambda v, r: v <= 2),
    Row("scene_ready", "6 launch->scene ready", "s", ".3f", "<= 3 s", lambda v, r: v <= 3, True),
    Row("rss_start", "6 RSS after start", "MB", ".0f", "<= 250 MB", lambda v, r: v <= 250),
    Row("rss_after", "6 RSS after 100k cmds", "MB", ".0f", "<= 250 MB", lambda v, r: v <= 250),
]


def summary(values: list[float], fmt: str) -> str:
    if not values:
        return "n/a"
    med = format(statistics.median(values), fmt)
    if len(values) == 1:
        return med
    return f"{med} ({format(min(values), fmt)}..{format(max(values), fmt)})"


def table(ours: list[Figures], ceiling: list[Figures], viewer: bool) -> str:
    header = ("row", "unit", "c2rviz median (min..max)", "ceiling median (min..max)", "ours/ceil",
              "target", "met")  # fmt: skip
    rows = [header]
    for row in ROWS:
        mine = [f[row.key] for f in ours if row.key in f]
        theirs = [f[row.key] for f in ceiling if row.key in f]
        ratio = None
        if mine and theirs and statistics.median(theirs):
            ratio = statistics.median(mine) / statistics.median(theirs)
        met = "-"
        if row.check is not None and mine and (ratio is not None or "x" not in row.target):
            met = "yes" if row.check(statistics.median(mine), ratio) else "NO"
        if row.viewer and not viewer:
            met = "no viewer"
        rows.append((
            row.label,
            row.unit,
            summary(mine, row.fmt),
            summary(theirs, row.fmt),
            f"{ratio:.2f}" if ratio is not None else "n/a",
            row.target,
            met,
        ))  # fmt: skip
    widths = [max(len(r[i]) for r in rows) for i in range(len(header))]
    lines = []
    for k, r in enumerate(rows):
        lines.append("| " + " | ".join(c.ljust(w) for c, w in zip(r, widths)) + " |")
        if k == 0:
            lines.append("|" + "|".join("-" * (w + 2) for w in widths) + "|")
    return "\n".join(lines)


def machine() -> str:
    cpu = "?"
    for line in Path("/proc/cpuinfo").read_text().splitlines():
        if line.startswith("model name"):
            cpu = line.split(":", 1)[1].strip()
            break
    mem_kib = int(re.search(r"MemTotal:\s+(\d+)", Path("/proc/meminfo").read_text()).group(1))  # type: ignore[union-attr]
    load = " ".join(f"{x:.2f}" for x in os.getloadavg())
    return (
        f"machine: {cpu}, {os.cpu_count()} cores, {mem_kib / 2**20:.0f} GiB; "
        f"{platform.system()} {platform.release()}; Python {platform.python_version()}; "
        f"load average {load}"
    )
