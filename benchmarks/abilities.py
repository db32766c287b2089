"""The abilities of the real program, measured: motion, Cartesian, collisions, the cell.

Usage: ``python benchmarks/abilities.py [--quick|--smoke] [--reps N] [--no-pin] [--no-cell]``
(``--smoke``: the test suite's run, every row on the least work).

Each repetition launches ``python -m c2rviz --port 0 --viser-port P`` (with
``--robot`` for each bundled robot, ``--guard on`` once, ``--cell`` once) as
separate processes, pinned to one CPU with the clients on the others as in
``run.py``, and drives them over TCP and viser's websocket from this process.
Prints one table: the median over the repetitions, the spread (min..max), and
the machine's 1-minute load average when the figures were taken (the machine is
shared). Figures only: nothing passes or fails on time. What each row measures:
``abilities_motion.py``, ``abilities_cartesian.py``, ``abilities_cell.py`` and docs/benchmarks.md.
"""

from __future__ import annotations

import argparse
import asyncio
import os
import statistics
import sys
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

from abilities_cartesian import ArmPlan, measure_cartesian, measure_guard, measure_ik_bystander
from abilities_cell import cell_supported, measure_cell
from abilities_motion import MotionPlan, measure_motion
from line_clients import Figure
from processes import ROOT, Launched, free_port, launch, pin_cpus
from report import machine

ROBOTS = {"motoman_sia20d": "motoman", "fanuc_lrmate200id": "fanuc", "kuka_lwr": "kuka"}


@dataclass(frozen=True)
class Plan:
    reps: int = 3
    motion: MotionPlan = field(default_factory=MotionPlan)
    arm: ArmPlan = field(default_factory=ArmPlan)
    cell_pipelined: int = 30_000


QUICK = Plan(
    reps=1,
    motion=MotionPlan(moves=2, far=0.6, speed=100, bystander_s=1.0, idle_s=0.5),
    arm=ArmPlan(ik_targets=5, lines=2, bystander_s=1.0, guard_round_trips=100),
    cell_pipelined=3_000,
)
SMOKE = Plan(
    reps=1,
    motion=MotionPlan(moves=2, far=0.3, speed=100, bystander_s=0.3, idle_s=0.2),
    arm=ArmPlan(ik_targets=2, lines=1, line_m=0.2, bystander_s=0.3, guard_round_trips=20),
    cell_pipelined=300,
)

# (key, label, unit, format, note)
Spec = tuple[str, str, str, str, str]
ROWS: list[Spec] = [
    ("motion_fps", "1 motion: pose frames/s to the page", "fps", ".0f", "median of the moves"),
    ("motion_gap_p50", "1 motion: frame interval p50", "ms", ".1f", ""),
    ("motion_gap_p99", "1 motion: frame interval p99", "ms", ".1f", ""),
    ("motion_lag_p50", "1 motion: page behind the plan p50", "ms", ".2f", "joint 0, from frames"),
    ("motion_lag_p99", "1 motion: page behind the plan p99", "ms", ".2f", ""),
    ("motion_lag_max", "1 motion: page behind the plan max", "ms", ".2f", "largest"),
    ("late_status_p50", "1 arrival reply - planned (status) p50", "ms", ".2f", "S has 1 ms steps"),
    ("late_status_p99", "1 arrival reply - planned (status) p99", "ms", ".2f", ""),
    ("late_plan_p50", "1 arrival reply - planned (ruckig) p50", "ms", ".2f", "incl. round trip"),
    ("late_plan_p99", "1 arrival reply - planned (ruckig) p99", "ms", ".2f", ""),
    ("motion_cpu_frame", "1 motion: server CPU per frame", "ms", ".3f", "all threads, minus idle"),
    ("by_idle_p50", "1 bystander `where` p50, arm at rest", "us", ".0f", "page connected"),
    ("by_idle_p99", "1 bystander `where` p99, arm at rest", "us", ".0f", ""),
    ("by_move_p50", "1 bystander `where` p50, during moves", "us", ".0f", ""),
    ("by_move_p99", "1 bystander `where` p99, during moves", "us", ".0f", ""),
]
for _robot, _short in ROBOTS.items():
    ROWS += [
        (f"ik_rand_p50_{_robot}", f"2 ik {_short}, random seed p50", "ms", ".2f", "round trip"),
        (f"ik_rand_p99_{_robot}", f"2 ik {_short}, random seed p99", "ms", ".2f", ""),
        (f"ik_rand_failed_{_robot}", f"2 ik {_short}, random seed unsolved", "%", ".0f", ""),
        (f"ik_near_p50_{_robot}", f"2 ik {_short}, near seed p50", "ms", ".2f", ""),
        (f"ik_near_p99_{_robot}", f"2 ik {_short}, near seed p99", "ms", ".2f", ""),
        (f"ik_near_failed_{_robot}", f"2 ik {_short}, near seed unsolved", "%", ".0f", ""),
        (f"movel_p50_{_robot}", f"2 movel 0.5 m {_short} p50", "ms", ".1f", "motion off"),
        (f"movel_max_{_robot}", f"2 movel 0.5 m {_short} max", "ms", ".1f", ""),
        (f"movel_refused_{_robot}", f"2 movel 0.5 m {_short} refused", "%", ".0f", "random lines"),
    ]
ROWS += [
    ("ik_by_idle_p50", "2 bystander `where` p50, no ik", "us", ".0f", "motoman"),
    ("ik_by_idle_p99", "2 bystander `where` p99, no ik", "us", ".0f", ""),
    ("ik_by_busy_p50", "2 bystander `where` p50, ik loop", "us", ".0f", ""),
    ("ik_by_busy_p99", "2 bystander `where` p99, ik loop", "us", ".0f", ""),
    ("ik_loop_rate", "2 the ik loop meanwhile", "ik/s", ".0f", ""),
]
for _key, _label in [
    ("guard_off_0", "off, 0 objects"),
    ("guard_on_0", "on, 0 objects"),
    ("guard_on_10", "on, 10 objects"),
    ("guard_off_10", "off, 10 objects"),
]:
    ROWS += [
        (f"{_key}_p50", f"3 j round trip, guard {_label} p50", "us", ".0f", ""),
        (f"{_key}_p99", f"3 j round trip, guard {_label} p99", "us", ".0f", ""),
        (f"{_key}_refused", f"3 j refused, guard {_label}", "%", ".1f", ""),
    ]
ROWS += [
    ("guard_first", "3 first `guard on` (builds the model)", "ms", ".1f", ""),
    ("port_open", "3 launch->port open", "s", ".3f", "motoman, defaults"),
    ("port_open_guard", "3 launch->port open, --guard on", "s", ".3f", ""),
    ("cell_ports_open", "4 cell of 3: launch->3 ports open", "s", ".3f", "port 0 each"),
    ("cell_alone", "4 cell: pipelined, one robot alone", "cmd/s", ",.0f", "motoman"),
    ("cell_busy_motoman_sia20d", "4 cell, all busy: motoman", "cmd/s", ",.0f", ""),
    ("cell_busy_fanuc_lrmate200id", "4 cell, all busy: fanuc", "cmd/s", ",.0f", ""),
    ("cell_busy_kuka_lwr", "4 cell, all busy: kuka", "cmd/s", ",.0f", ""),
    ("cell_busy_sum", "4 cell, all busy: sum", "cmd/s", ",.0f", ""),
]
del _robot, _short, _key, _label


def launch_c2rviz(*extra: str) -> Launched:
    argv = [sys.executable, "-m", "c2rviz", "--port", "0", "--viser-port", str(free_port())]
    return launch([*argv, *extra], viewer=True)


def one_repetition(plan: Plan, cell: bool, log: Callable[[str], None]) -> dict[str, Figure]:
    out: dict[str, Figure] = {}
    for robot in ROBOTS:
        proc = launch_c2rviz("--robot", robot)
        try:
            if robot == "motoman_sia20d":
                log("motion")
                out |= asyncio.run(measure_motion(proc, plan.motion))
                log("ik bystander")
                out |= measure_ik_bystander(proc, plan.arm)
            log(f"ik and movel, {robot}")
            out |= measure_cartesian(proc, robot, plan.arm)
        finally:
            proc.stop()
    log("guard")
    proc = launch_c2rviz()
    try:
        assert proc.port_open_s is not None
        out["port_open"] = Figure(proc.port_open_s)
        out |= measure_guard(proc, plan.arm)
    finally:
        proc.stop()
    proc = launch_c2rviz("--guard", "on")
    proc.stop()
    assert proc.port_open_s is not None
    out["port_open_guard"] = Figure(proc.port_open_s)
    if cell:
        log("cell")
        out |= measure_cell(plan.cell_pipelined)
    return out


def table(reps: list[dict[str, Figure]]) -> str:
    header = ("row", "unit", "median (min..max)", "load 1-min", "note")
    rows = [header]
    for key, label, unit, fmt, note in ROWS:
        figures = [rep[key] for rep in reps if key in rep]
        if not figures:
            continue
        values = [f.value for f in figures]
        med = format(statistics.median(values), fmt)
        if len(values) > 1:
            med += f" ({format(min(values), fmt)}..{format(max(values), fmt)})"
        loads = [f.load for f in figures]
        spread = max(loads) - min(loads) >= 0.05
        load = f"{min(loads):.1f}" + (f"..{max(loads):.1f}" if spread else "")
        rows.append((label, unit, med, load, note))
    widths = [max(len(r[i]) for r in rows) for i in range(len(header))]
    lines = []
    for k, r in enumerate(rows):
        lines.append("| " + " | ".join(c.ljust(w) for c, w in zip(r, widths)) + " |")
        if k == 0:
            lines.append("|" + "|".join("-" * (w + 2) for w in widths) + "|")
    return "\n".join(lines)


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="one short repetition (for CI)")
    parser.add_argument("--smoke", action="store_true", help="every row, the least work")
    parser.add_argument("--reps", type=int, help="repetitions (default 3; 1 with --quick)")
    parser.add_argument("--no-pin", action="store_true", help="let the OS place the processes")
    parser.add_argument("--no-cell", action="store_true", help="leave out row 4 (the cell)")
    args = parser.parse_args(argv)
    plan = SMOKE if args.smoke else QUICK if args.quick else Plan()
    reps = max(1, args.reps) if args.reps is not None else plan.reps

    def log(text: str) -> None:
        print(f"  {text}", file=sys.stderr, flush=True)

    print(machine() + f"; {pin_cpus(not args.no_pin)}", flush=True)
    cell = not args.no_cell and cell_supported()
    figures = []
    for rep in range(reps):
        log(f"repetition {rep + 1}/{reps}")
        figures.append(one_repetition(plan, cell, log))
    m = plan.motion
    print(
        f"{reps} repetition(s) of {ROOT}; motion: {m.moves} moves of joint 0 by {m.far:g} rad "
        f"at speed {m.speed:g} %; ik: {plan.arm.ik_targets} targets per seed; movel: "
        f"{plan.arm.lines} lines; guard: {plan.arm.guard_round_trips} round trips per row"
        + ("" if cell else "; row 4 left out (no --cell in this c2rviz, or --no-cell)")
    )
    print(table(figures))
    print(f"load average at the end: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
