"""Assertions a controller's tests need, over a ``c2rviz.Client`` (any server, any door).

- ``assert_arrives(robot, within=S)``: the move running now comes to rest at its target
  within ``S`` seconds of the server's clock (and, with ``at=``, that target is the one
  meant).
- ``with assert_no_collision_during(robot): ...``: nothing collides while the block runs
  and the moves it started come to rest (every frame is checked: the server's live
  collision check, read from a ``watch`` stream).
- ``assert_part_at(robot, name, pose, tol)``: part ``name`` is at ``pose`` (docs/parts.md).
- ``assert_goals_met(robot)``: every goal is met (``score``).
"""

from __future__ import annotations

import contextlib
import math
import threading
from collections.abc import Iterable, Iterator, Sequence

from ..clients.client import Client
from ..clients.records import State, read_pairs, read_stream_line
from ..clients.stream import WatchStream


def _values(values: Sequence[float]) -> str:
    return ",".join(f"{value:.6g}" for value in values)


def assert_arrives(
    robot: Client,
    within: float,
    at: Sequence[float] | None = None,
    tol: float = 1e-6,
) -> None:
    """The arm's current move ends at its target within ``within`` seconds.

    Start the move with ``motion follow`` (the call returns at once), then assert; a move
    with ``motion on`` has arrived already when its call returns. Waits for the arrival
    (in virtual time, at once).

    Args:
        robot: A connection to the server.
        within: Longest time left to arrive [s of the server's clock].
        at: The joint values it must arrive at [the connection's units], if any.
        tol: How near the target counts as there [the connection's units].

    Raises:
        AssertionError: it would take longer, came to rest short of the target it had
            when asked (a stop or another move meanwhile), or arrived elsewhere than ``at``
            (give ``at`` to catch a move stopped before this was called).
    """
    target = robot.target()
    status = robot.status()
    if status.moving and status.seconds_left > within:
        raise AssertionError(
            f"the arm arrives in {status.seconds_left:.3f} s, not within {within:g} s "
            f"(target {_values(target)})"
        )
    robot.wait()
    where = robot.where()
    if any(abs(w - t) > tol for w, t in zip(where, target)):
        raise AssertionError(
            f"the arm came to rest at {_values(where)}, short of its target {_values(target)} "
            "(stopped, or another move took over)"
        )
    if at is not None and (
        len(at) != len(where) or any(abs(w - a) > tol for w, a in zip(where, at))
    ):
        raise AssertionError(f"the arm arrived at {_values(where)}, not at {_values(at)}")


def _rotation(roll: float, pitch: float, yaw: float) -> list[list[float]]:
    """R = Rz(yaw) Ry(pitch) Rx(roll), as the server's poses mean it [rad]."""
    cr, sr, cp, sp, cy, sy = (f(a) for a in (roll, pitch, yaw) for f in (math.cos, math.sin))
    return [
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
        [-sp, cp * sr, cp * cr],
    ]


def _angle_between(a: Sequence[float], b: Sequence[float]) -> float:
    """The angle of the rotation from rpy ``a`` to rpy ``b`` [rad]."""
    ra, rb = _rotation(*a), _rotation(*b)
    trace = sum(ra[k][i] * rb[k][i] for i in range(3) for k in range(3))
    return math.acos(max(-1.0, min(1.0, (trace - 1.0) / 2.0)))


def assert_part_at(
    robot: Client,
    name: str,
    pose: Sequence[float],
    tol: float = 0.001,
    tol_angle: float | None = None,
) -> None:
    """Part ``name`` is at ``pose`` (x, y, z [m], roll, pitch, yaw [the connection's angle
    unit], in its robot's base frame), within ``tol`` [m] and ``tol_angle`` (None: any
    orientation; the connection's unit).

    Raises:
        AssertionError: naming where the part is, and its state (``held``, ``resting on
            table``), or that there is no such part.
    """
    reply = robot.ask(f"part {name}")
    if not reply.startswith("ok "):
        raise AssertionError(f"part {name}: {reply} ({robot.ask('parts')})")
    words = reply.split(" ", 2)
    where, state = [float(v) for v in words[1].split(",")], words[2]
    distance = math.dist(where[:3], pose[:3])
    scale = math.pi / 180.0 if robot.in_degrees else 1.0
    message = f"part {name} is at {_values(where)} ({state}), not at {_values(pose)}"
    if distance > tol:
        raise AssertionError(f"{message}: {distance * 1000:.1f} mm off")
    if tol_angle is not None and len(pose) == 6:
        angle = _angle_between([v * scale for v in where[3:]], [v * scale for v in pose[3:]])
        if angle > tol_angle * scale:
            raise AssertionError(f"{message}: turned {angle / scale:.3g} off")


def assert_goals_met(robot: Client) -> None:
    """Every goal set with ``goal`` is met.

    Raises:
        AssertionError: the ``score`` (which goals are how far off, which parts missing)
            and where every part is.
    """
    reply = robot.ask("score")
    if reply == "ok no goals":
        raise AssertionError("no goals are set (goal NAME POSE)")
    met = reply.split()[1] if reply.startswith("ok ") else ""
    count, _, total = met.partition("/")
    if not count or count != total:
        raise AssertionError(f"not every goal is met: {reply[3:]}; parts: {robot.ask('parts')}")


class _Collisions:
    """A watch stream read on a thread: the collisions it tells, with the time of each."""

    def __init__(self, stream: WatchStream) -> None:
        self.stream = stream
        self.found: list[tuple[float, list[tuple[str, str]]]] = []
        self.replies = 0
        self._t = math.nan
        self._answered = threading.Condition()
        self._thread = threading.Thread(target=self._read, name="c2rviz-watch", daemon=True)
        self._thread.start()

    def _read(self) -> None:
        with contextlib.suppress(OSError, ValueError):
            for line in self.stream.lines():
                record = read_stream_line(line)
                if isinstance(record, State):
                    self._t = record.t
                elif record is not None and record.kind == "collision":
                    pairs = read_pairs(record.detail)
                    if pairs:
                        self.found.append((self._t, pairs))
                elif record is None:  # a reply to our own line: all before it is in
                    with self._answered:
                        self.replies += 1
                        self._answered.notify_all()

    def join(self) -> None:
        """The stream is closed: the reading thread ends."""
        self._thread.join(timeout=60)

    def sync(self) -> None:
        """Wait until every line the stream had written before now has been read."""
        with self._answered:
            asked = self.replies + 1
            # `watch` again (the same rate): its reply comes after every line written before,
            # and a connection whose last line is `watch` only listens, so a virtual clock
            # does not wait for it.
            self.stream.send("watch")
            if not self._answered.wait_for(lambda: self.replies >= asked, timeout=60):
                raise AssertionError("the watch stream went quiet: cannot tell the collisions")


@contextlib.contextmanager
def assert_no_collision_during(
    robot: Client, allowed: Iterable[tuple[str, str]] = ()
) -> Iterator[None]:
    """Nothing collides while the block runs and the arm comes to rest after it.

    Every frame the server shows is checked (its live check, read from a ``watch``
    stream of a connection of its own); on leaving the block the arm is waited for
    (``wait``), and its pose at rest is checked too.

    Args:
        robot: A connection to the server (the block drives the arm, through it or not).
        allowed: Pairs that may touch (``("finger_l", "box")``), in either order.

    Raises:
        AssertionError: naming each pair that collided and when [s of the server's clock].
    """
    ok = {frozenset(pair) for pair in allowed}
    with robot.watch() as stream:  # every frame: each state dates the events after it
        watcher = _Collisions(stream)
        robot.collisions()  # checking starts now: every frame from here on
        watcher.sync()
        yield
        robot.wait()
        robot.collisions()  # the pose at rest, checked now rather than a frame later
        watcher.sync()
    watcher.join()
    hits = [
        (t, [pair for pair in pairs if frozenset(pair) not in ok]) for t, pairs in watcher.found
    ]
    hits = [(t, pairs) for t, pairs in hits if pairs]
    if hits:
        said = "; ".join(
            f"{', '.join(f'{a}~{b}' for a, b in pairs)} at t={t:.3f} s" for t, pairs in hits[:10]
        )
        more = f" (and {len(hits) - 10} more)" if len(hits) > 10 else ""
        raise AssertionError(f"collision during the block: {said}{more}")
