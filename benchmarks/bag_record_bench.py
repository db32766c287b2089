"""What recording the bag costs beside NAME.txt and NAME.csv, in a running world at 100 Hz.

Run: ``python benchmarks/bag_record_bench.py [--quick] [--seconds S]``.

A world of 1 and of 8 motoman_sia20d arms (a cell), each moving without pause at
speed 100 (``motion`` travel: the world samples every arm 100 times a second, as a
controller's moves would), on the real clock and a real asyncio loop. The CPU time
of this process over ``S`` seconds is measured three ways, one after the other:

- ``moving``: nobody records;
- ``txt+csv``: ``record NAME all`` without the bag (the recorders only: NAME.txt,
  NAME.csv for every arm);
- ``+bag``: the same with the bag NAME/ (``/joint_states`` and ``/tf`` of every arm
  each frame, namespaced in the cell).

Each line prints the CPU used as a share of one core. Goal (issue 25): the bag adds
at most 10 % CPU over recording without it at 100 Hz, read as ``+bag`` minus
``txt+csv`` in points of one core (``bag adds``); ``bag/rec`` is the bag's cost over
the recorders' own (their cost over ``moving``). The recordings are stopped outside
the measured time, without the page (the page's cost is the record page's).
Figures only: nothing here passes or fails.
"""

from __future__ import annotations

import argparse
import asyncio
import sys
import tempfile
import time
from collections.abc import Sequence
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from c2rviz.observers.recordings import Recordings  # noqa: E402
from c2rviz.robot import Robot  # noqa: E402
from c2rviz.world.observer import Observer  # noqa: E402
from c2rviz.world.world import World  # noqa: E402

__all__ = ["main"]

URDF = ROOT / "robots" / "motoman_sia20d" / "robot.urdf"


class Mover(Observer):
    """Sends each arm to a new random target as soon as it arrives."""

    def __init__(self, world: World, rng: np.random.Generator) -> None:
        self.world = world
        self.rng = rng

    def go(self, name: str) -> None:
        state = self.world.state(name)
        low, high = np.array(state.robot.lower), np.array(state.robot.upper)
        target = (low + (high - low) * self.rng.uniform(0.3, 0.7, len(low))).tolist()
        self.world.travels.go(state, target, 1.0, "bench", wait=False)

    def on_arrived(self, robot: str) -> None:
        asyncio.get_running_loop().call_soon(self.go, robot)


async def cpu_share(seconds: float) -> float:
    """CPU time of this process over ``seconds`` of wall time, as a share of one core [%]."""
    cpu, wall = time.process_time(), time.perf_counter()
    await asyncio.sleep(seconds)
    return (time.process_time() - cpu) / (time.perf_counter() - wall) * 100


async def measure(count: int, seconds: float, folder: Path) -> dict[str, float]:
    robot = Robot.from_urdf(URDF, "base_link", "link_t")
    names = [f"r{k}" for k in range(count)]
    world = World({name: robot for name in names})
    mover = Mover(world, np.random.default_rng(4))
    world.add_observers([mover])
    for name in names:
        mover.go(name)
    await asyncio.sleep(1.0)  # everything moving, caches warm
    shares = {"moving": await cpu_share(seconds)}
    for label, bag in (("txt+csv", False), ("+bag", True)):
        desk = Recordings(world, folder, bag=bag)
        desk.start(f"{label.strip('+')}{count}", names[0], every=True)
        await asyncio.sleep(0.5)
        shares[label] = await cpu_share(seconds)
        await desk.close("done")
    world.close()
    return shares


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="2 s per measure instead of 10")
    parser.add_argument("--seconds", type=float, help="seconds per measure")
    args = parser.parse_args(argv)
    seconds = args.seconds or (2.0 if args.quick else 10.0)
    print(f"recording at 100 Hz, motoman_sia20d arms always moving ({seconds:g} s each, CPU "
          "of this process as a share of one core)")  # fmt: skip
    print(f"{'arms':>4s} {'moving':>7s} {'txt+csv':>8s} {'+bag':>7s} {'bag adds':>9s} "
          f"{'goal':>6s} {'bag/rec':>8s}")  # fmt: skip
    with tempfile.TemporaryDirectory() as temporary:
        for count in (1, 8):
            s = asyncio.run(measure(count, seconds, Path(temporary)))
            adds = s["+bag"] - s["txt+csv"]
            own = s["txt+csv"] - s["moving"]
            ratio = f"{adds / own:7.2f}x" if own > 0.05 else "      -"
            print(
                f"{count:4d} {s['moving']:6.1f}% {s['txt+csv']:7.1f}% {s['+bag']:6.1f}% "
                f"{adds:+8.1f}% {'<=10%':>6s} {ratio}"
            )
    print("goal: the bag adds <= 10 % of one core over recording without it (issue 25)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
