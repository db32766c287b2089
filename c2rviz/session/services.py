"""What every session shares besides the world: handed to each session, no singletons.

The app makes one ``Services`` for the program and passes it to every door and to
the view; a test makes one around its own world. It holds the world, how sessions
start and what a client may cost, the random source of ``rand``, the worker that
runs CPU work off the event loop, and the observers the verbs drive: ``watch``
streams, trails, recordings, and the guard's watch over running guarded moves.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..observers.recordings import DEFAULT_FOLDER, Exporter, Recordings
from ..observers.trail import DEFAULT_TRAIL_POINTS, TrailKeeper
from ..observers.watch import WatchHub
from ..world.world import World
from .guard_watch import GuardWatch
from .move_requests import world_request
from .settings import ServerLimits, SessionDefaults
from .worker import Worker


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
