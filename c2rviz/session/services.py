"""What every session shares, how each starts, what one client may cost, and the modes a
session keeps; handed to each session, no singletons.

The app makes one ``Services`` for the program and passes it to every door and to
the view; a test makes one around its own world. It holds the world, how sessions
start and what a client may cost, the random source of ``rand``, the worker that
runs CPU work off the event loop, and the observers the verbs drive: ``watch``
streams, trails, recordings, and the guard's watch over running guarded moves.

``ServerLimits`` bound what one client of a door may cost (README: "Limits");
``SessionDefaults`` say how a new session starts (each may change its own with a
command). Both are plain settings the app fills in from ``cmdinterpreter.ini`` and the
flags (``app.config``).

``Modes`` are a session's lasting modes, and the setters through which a door changes
them: a door never assigns a session's fields, it calls these
(``tests/app/test_one_way_in`` keeps it so); the text verbs' handlers set the same
fields (``motion``, ``speed``, ``lspeed``, ``guard``).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..observers.recordings import DEFAULT_FOLDER, Exporter, Recordings
from ..observers.trail import DEFAULT_TRAIL_POINTS, TrailKeeper
from ..observers.watch import WatchHub
from ..protocol.limits import default, default_s
from ..world.world import World
from .guard_watch import GuardWatch, world_request
from .worker import Worker


@dataclass(frozen=True)
class ServerLimits:
    """What one client of the text port may cost the server (README: "Limits"); the
    defaults and bounds are the ``text`` rows of ``limits.LIMITS``."""

    max_line: int = default("text", "max_line")
    """Longest line [bytes]; longer closes the connection."""
    max_clients: int = default("text", "max_clients")
    """Clients connected at once; one more is told so and closed."""
    max_unread: int = default("text", "max_unread")
    """Replies a client has not read [bytes]; more closes the connection."""
    partial_timeout_s: float = default_s("text", "partial_timeout_s")
    """How long a started line may stay unfinished [s]."""
    max_sleep_s: float = default_s("text", "max_sleep_s")
    """Longest ``sleep`` [s]."""


@dataclass(frozen=True)
class SessionDefaults:
    """How a new connection starts (each may change its own with a command)."""

    motion: str = "off"
    """``off`` (moves shown at once, the seed's way), ``on`` or ``follow``."""
    speed: float = 50.0
    """Moves at this % of each joint's velocity limit (1..100)."""
    guard: bool = False
    """Refuse commands whose target or path collides."""
    lspeed: float = 0.25
    """``movel``'s tool speed [m/s] (as UR's movel)."""
    plan_around: bool = False
    """With the guard: plan around what a joint-space move's straight path would hit
    (``guard plan``) instead of refusing it."""
    plan_timeout_s: float = 1.0
    """Most time a plan searches [s] (``plan``, ``guard plan``)."""
    plan_seed: int | None = None
    """The planner's seed, so a run repeats (None: a fresh one each plan)."""
    plan_step_rad: float = math.radians(1.0)
    """Most a revolute joint moves between two checks of a path [rad] (5 mm prismatic)."""
    plan_tool_step_m: float | None = 0.005
    """Most the tool travels between two checks of a path [m]; None: no bound."""


class Modes:
    """The modes a ``session.Session`` keeps between commands (see its attributes)."""

    source: str
    motion: str
    speed: float
    lspeed: float
    guard: bool
    plan_around: bool
    hangup: str | None

    def set_source(self, source: str) -> None:
        """Name who speaks as ``source`` from now on (a connection, once its peer is known)."""
        self.source = source

    def take_hangup(self) -> str | None:
        """The hangup a handler asked for (``bye``, ``quit`` or None), cleared."""
        hangup, self.hangup = self.hangup, None
        return hangup

    def set_motion(self, mode: str) -> None:
        """Move ``off`` (at once), ``on`` (replies on arrival) or ``follow`` from now on."""
        self.motion = mode

    def set_speed(self, percent: float) -> None:
        """Move at ``percent`` of the joints' limits from now on."""
        self.speed = percent

    def set_lspeed(self, m_s: float) -> None:
        """Straight lines at ``m_s`` [m/s] from now on."""
        self.lspeed = m_s

    def set_guard(self, on: bool, plan_around: bool = False) -> None:
        """Refuse (``plan_around``: plan around) what would collide, from now on."""
        self.guard = on
        self.plan_around = on and plan_around


@dataclass(eq=False)
class Services:
    """The program's shared parts, around one world.

    Attributes:
        world: The shared state.
        limits: What one client may cost.
        defaults: How a new session starts.
        rng: Random source for ``rand``.
        record_dir: Where recordings go.
        trail_points: Points a trail keeps at most.
        exporters: What a finished recording also writes (the app gives NAME.html's).
        watch: The ``watch`` streams (made here).
        trails: The trails (made here).
        recordings: The recordings (made here).
        worker: CPU work off the event loop (made here).
        guards: The guarded moves running, re-checked when the world changes (made here).
    """

    world: World
    limits: ServerLimits = field(default_factory=ServerLimits)
    defaults: SessionDefaults = field(default_factory=SessionDefaults)
    rng: np.random.Generator = field(default_factory=np.random.default_rng)
    record_dir: Path = DEFAULT_FOLDER
    trail_points: int = DEFAULT_TRAIL_POINTS
    exporters: Sequence[Exporter] = ()
    watch: WatchHub = field(init=False)
    trails: TrailKeeper = field(init=False)
    recordings: Recordings = field(init=False)
    worker: Worker = field(init=False)
    guards: GuardWatch = field(init=False)
    _clients: dict[str, int] = field(init=False, default_factory=dict)

    def __post_init__(self) -> None:
        self.watch = WatchHub(self.world)
        self.world.faults.bind(self.rng.spawn(1)[0], self.watch.origin)  # rand's draws unchanged
        self.trails = TrailKeeper(self.world, self.trail_points)
        self.recordings = Recordings(self.world, self.record_dir, self.watch.event, self.exporters)
        self.worker = Worker()
        self.guards = GuardWatch(
            self.world,
            self.worker,
            lambda robot, resolution, start: world_request(
                self.world, robot, resolution, start, [start], still_only=True
            ),
        )
        self.world.add_observers([self.guards])

    def count_clients(self, door: str, count: int) -> None:
        """``door`` has ``count`` clients now; the world tells the total to its observers."""
        self._clients[door] = count
        self.world.tell_clients(sum(self._clients.values()))

    @property
    def client_count(self) -> int:
        """Clients connected through every door."""
        return sum(self._clients.values())

    def close(self) -> None:
        """The program stops: no more work off the loop, frames or checks."""
        self.worker.close()
        self.world.close()
