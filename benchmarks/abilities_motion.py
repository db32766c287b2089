"""Abilities row 1, "Motion takes time": what a long move costs and how the page sees it.

One motoman server with its viewer; a websocket client decodes every frame
(``loadgen.ViewerClient``). Client A says ``motion on`` and moves joint 0 back
and forth between 0 and ``far`` [rad] at ``speed`` %, each move from rest
(the reply comes on arrival). For each move:

- frames/s reaching the page and the interval between two pose frames;
- how far the page's arm is behind the plan: joint 0 is read back from the
  orientation of its child link in each frame (``SetOrientationMessage``), and
  the same ruckig plan, computed here by ``c2rviz.motion`` from the same limits,
  says at which plan time the arm was there; lag = (arrival of the frame - the
  move's send) - that plan time, over the frames 5-95 % of the way;
- arrival: the reply's round trip minus the planned duration, the duration taken
  two ways: from ``status`` on a second connection (``ok moving S``, sent right
  after the move; S has ms resolution) and from the local plan (which includes
  the request's and reply's transit, ~0.1 ms);
- the server's CPU per frame (all threads: loop, viser) during the moves, minus
  its idle CPU rate (taken after the moves, the arm at rest), divided by the pose
  frames the page received.

Then a bystander process does ``where`` request/reply, first with the arm at
rest, then while moves run back to back.
"""

from __future__ import annotations

import asyncio
import re
import sys
import time
from dataclasses import dataclass
from typing import Any

import loadgen
import numpy as np
import pinocchio as pin
from line_clients import Bystander, Figure, LineClient, percentile
from processes import ROOT, Launched

sys.path.insert(0, str(ROOT))  # this tree's c2rviz, not an installed one

from c2rviz.motion.limits import motion_limits  # noqa: E402
from c2rviz.motion.planner import Motion  # noqa: E402
from c2rviz.robot.model import Robot  # noqa: E402
from c2rviz.view.link_tree import LinkTree  # noqa: E402
from c2rviz.view.robot_view import node_name  # noqa: E402

__all__ = ["MotionPlan", "measure_motion"]


@dataclass(frozen=True)
class MotionPlan:
    """How much of row 1 one repetition does."""

    moves: int = 10
    far: float = 2.0
    """Joint 0's far position [rad]."""
    speed: float = 50.0
    """% of the limits: a 2 rad move of the motoman's joint 0 then lasts ~3.2 s."""
    bystander_s: float = 6.0
    idle_s: float = 2.0


class JointReader:
    """Joint 0 of the chain read back from its child link's orientation in its parent
    link's frame (the page nests each link's frame in its parent's)."""

    def __init__(self, robot: Robot) -> None:
        tree = LinkTree(robot, node_name)
        home = [0.0] * robot.n
        turned = [0.1] + home[1:]
        rotations = {}
        for q in (home, turned):
            pin.forwardKinematics(robot.model, robot.data, robot.configuration(q))
            rotations[q[0]] = {
                link.name: tree.local(link, robot.data).rotation.copy() for link in tree.links
            }
        # The first link that turns with joint 0 (its child).
        first = next(
            link
            for link in tree.links
            if not np.allclose(rotations[0.0][link.name], rotations[0.1][link.name])
        )
        self.link = first.name
        # The viewer's node (c2rviz/view/robot_view.py).
        self.node = f"/robots/{robot.name}/links/{first.path}"
        self.home = rotations[0.0][self.link]
        self.axis = pin.log3(rotations[0.1][self.link] @ self.home.T) / 0.1

    def angle(self, wxyz: tuple[float, float, float, float]) -> float:
        w, x, y, z = wxyz
        rotation = pin.Quaternion(w, x, y, z).toRotationMatrix()
        return float(pin.log3(rotation @ self.home.T) @ self.axis)


def _plan_time(motion: Motion, angle: float, start: float, end: float, duration: float) -> float:
    """The plan time [s] at which joint 0 passes ``angle`` (monotonic move, bisection)."""
    low, high = 0.0, duration
    sign = 1.0 if end > start else -1.0
    for _ in range(50):
        mid = 0.5 * (low + high)
        if sign * (motion.sample(mid)[0][0] - angle) < 0:
            low = mid
        else:
            high = mid
    return 0.5 * (low + high)


@dataclass
class Move:
    start: float
    end: float
    sent: float
    replied: float
    status_left: float
    status_at: float


def _one_move(a: LineClient, b: LineClient, n: int, start: float, end: float) -> Move:
    sent = a.send("j " + ",".join([f"{end:g}"] + ["0"] * (n - 1)))
    for _ in range(1000):  # B's line may reach the server before A's: ask again
        status, rtt = b.ask("status")
        status_at = time.perf_counter() - rtt / 2
        if match := re.fullmatch(r"ok moving ([\d.]+)", status):
            break
    else:
        raise RuntimeError(f"expected 'ok moving S' right after the move, got {status!r}")
    reply, replied = a.read()
    if reply != "ok":
        raise RuntimeError(f"the move was refused: {reply!r}")
    return Move(start, end, sent, replied, float(match.group(1)), status_at)


async def measure_motion(proc: Launched, plan: MotionPlan) -> dict[str, Figure]:
    """Row 1 on a running motoman server with a viewer; returns figures by key."""
    assert proc.url is not None
    robot = Robot.from_urdf(ROOT / "robots/motoman_sia20d/robot.urdf", "base_link", "link_t")
    limits = motion_limits(robot)
    reader = JointReader(robot)
    angles: list[tuple[float, float]] = []  # (arrival, joint 0 [rad]) from each frame

    def on_messages(at: float, messages: list[dict[str, Any]]) -> None:
        for m in messages:
            if m.get("type") == "SetOrientationMessage" and m.get("name") == reader.node:
                angles.append((at, reader.angle(m["wxyz"])))

    viewer = loadgen.ViewerClient(loadgen.ws_url(proc.url))
    viewer.on_messages = on_messages
    task = asyncio.create_task(viewer.run())
    a, b = LineClient(proc.address), LineClient(proc.address)
    out: dict[str, Figure] = {}
    try:
        await asyncio.wait_for(viewer.replay_done.wait(), 30)
        a.ok("motion on")
        a.ok(f"speed {plan.speed:g}")
        moves: list[Move] = []
        cpu0 = proc.cpu_s()
        for k in range(plan.moves):
            start, end = (0.0, plan.far) if k % 2 == 0 else (plan.far, 0.0)
            moves.append(await asyncio.to_thread(_one_move, a, b, robot.n, start, end))
        cpu = proc.cpu_s() - cpu0
        # The idle rate after the moves, the arm at rest: just after the start the page
        # still makes its marker meshes in a thread, which is not what a frame costs.
        await asyncio.sleep(0.3)
        cpu0 = proc.cpu_s()
        await asyncio.sleep(plan.idle_s)
        idle_rate = (proc.cpu_s() - cpu0) / plan.idle_s
        window = moves[-1].replied - moves[0].sent
        _motion_figures(out, moves, viewer, angles, limits, plan.speed / 100.0)
        frames = sum(1 for f in viewer.frames if f.poses and moves[0].sent <= f.at)
        out["motion_cpu_frame"] = Figure((cpu - idle_rate * window) / frames * 1e3)

        by = Bystander(proc.address, plan.bystander_s, "where")
        times, _ = await asyncio.to_thread(by.result)
        out["by_idle_p50"] = Figure(percentile(times, 50) * 1e6)
        out["by_idle_p99"] = Figure(percentile(times, 99) * 1e6)
        by = Bystander(proc.address, plan.bystander_s, "where")
        k = 0
        while by.running():
            start, end = (0.0, plan.far) if k % 2 == 0 else (plan.far, 0.0)
            await asyncio.to_thread(_one_move, a, b, robot.n, start, end)
            k += 1
        times, _ = await asyncio.to_thread(by.result)
        out["by_move_p50"] = Figure(percentile(times, 50) * 1e6)
        out["by_move_p99"] = Figure(percentile(times, 99) * 1e6)
        if k % 2:  # back home, for whatever runs next
            await asyncio.to_thread(_one_move, a, b, robot.n, plan.far, 0.0)
    finally:
        a.close()
        b.close()
        task.cancel()
        await asyncio.gather(task, return_exceptions=True)
    return out


def _motion_figures(
    out: dict[str, Figure],
    moves: list[Move],
    viewer: loadgen.ViewerClient,
    angles: list[tuple[float, float]],
    limits: Any,
    speed: float,
) -> None:
    rates, intervals, lags, late_status, late_plan = [], [], [], [], []
    for move in moves:
        motion = Motion(limits, [move.start] + [0.0] * (limits.n - 1))
        duration = motion.move_to([move.end] + [0.0] * (limits.n - 1), 0.0, speed)
        late_plan.append((move.replied - move.sent) - duration)
        late_status.append(move.replied - (move.status_at + move.status_left))
        arrivals = [f.at for f in viewer.frames if f.poses and move.sent <= f.at <= move.replied]
        rates.append(len(arrivals) / (move.replied - move.sent))
        intervals += [t1 - t0 for t0, t1 in zip(arrivals, arrivals[1:])]
        span = move.end - move.start
        for at, angle in angles:
            if move.sent <= at <= move.replied and 0.05 <= (angle - move.start) / span <= 0.95:
                tau = _plan_time(motion, angle, move.start, move.end, duration)
                lags.append((at - move.sent) - tau)
    if not intervals or not lags:
        raise RuntimeError("no pose frames reached the page during the moves")
    out["motion_fps"] = Figure(sorted(rates)[len(rates) // 2])
    out["motion_gap_p50"] = Figure(percentile(intervals, 50) * 1e3)
    out["motion_gap_p99"] = Figure(percentile(intervals, 99) * 1e3)
    out["motion_lag_p50"] = Figure(percentile(lags, 50) * 1e3)
    out["motion_lag_p99"] = Figure(percentile(lags, 99) * 1e3)
    out["late_status_p50"] = Figure(percentile(late_status, 50) * 1e3)
    out["late_status_p99"] = Figure(percentile(late_status, 99) * 1e3)
    out["late_plan_p50"] = Figure(percentile(late_plan, 50) * 1e3)
    out["late_plan_p99"] = Figure(percentile(late_plan, 99) * 1e3)
    out["motion_lag_max"] = Figure(max(abs(x) for x in lags) * 1e3)
