"""What the page process is handed when it starts: how to serve the page, and the world
as it is now (``Hello``), and the ``snapshot`` that resyncs a page that fell behind.

Both travel pickled inside one channel message (``page_channel``): they go once per
start of the page process (or after it fell behind), from our process to the child it
started, and they carry the robots' models and the workcell objects, which msgpack
cannot. Every frame after them is plain msgpack (``page_link``).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import pinocchio as pin

from ..collision.workcell import WorkcellObject
from ..motion.limits import MotionLimits
from ..robot.model import Robot
from ..session.services import Services, SessionDefaults
from ..session.session import Session
from ..world.state import Marker
from .page_cell import camera_rows, fault_banners, goal_rows, part_rows
from .page_frame import trail_state

__all__ = ["RECENT_COMMANDS", "Hello", "PageConfig", "RobotSnapshot", "Snapshot", "snapshot"]

RECENT_COMMANDS = 8
"""Lines the 'last commands' readout keeps: ``panel.RECENT_COMMANDS`` (not imported, as
``panel`` loads viser, which the program never needs with ``--page-process``)."""


@dataclass(frozen=True)
class PageConfig:
    """How the page process serves the page.

    Attributes:
        host, port: Where (0: a free port; on a restart, the port the tabs know).
        hz: Most sends per second [1/s].
        origins, token, max_viewers: The door's policy (``policy.DoorPolicy``).
        title: The cell's or robot's name, or None (the robots' names).
        defaults: How a session starts (the page's follow the motion mode).
        trail_points: Points a trail keeps at most.
        log_level: The program's logging level (the page process logs alike).
        recent_commands: Lines the 'last commands' readout keeps.
        lighting: How the page lights its scene (``adapter.LIGHTINGS``).
    """

    host: str
    port: int
    hz: float
    origins: tuple[str, ...]
    token: str | None
    max_viewers: int
    title: str | None
    defaults: SessionDefaults
    trail_points: int
    log_level: int
    recent_commands: int
    lighting: str = "studio"

    @property
    def frame_s(self) -> float:
        """Time between two frames published [s]."""
        return 1.0 / self.hz

    def again(self, port: int) -> PageConfig:
        """The same, on ``port`` (a restart serves where the tabs look)."""
        return dataclasses.replace(self, port=port)


@dataclass(frozen=True)
class RobotSnapshot:
    """One robot, as it is now (SI units)."""

    robot: Robot
    origin: pin.SE3
    limits: MotionLimits
    q: tuple[float, ...]
    target: tuple[float, ...]
    opening: float
    tool: pin.SE3
    ghost: bool
    markers: list[Marker]
    moving: bool
    seconds_left: float
    speed: float
    objects: list[WorkcellObject]
    collisions: list[tuple[str, str]]


@dataclass(frozen=True)
class Snapshot:
    """The world as the page shows it, now.

    Attributes:
        t: The clock's time [s].
        watch_origin: The time the page's times count from [s of the clock].
        frame_s: The world's time between two samples of a moving arm [s].
        robots: Each robot, by name, the default first.
        trails: The robots whose trail is on, each with how often it was cleared.
        clients: Clients connected through every door.
        commands: The last commands, newest first, and whether each was accepted.
        parts, goals, cameras: Their rows (``page_cell``).
        banners: Each robot's fault banner that is not empty, by name.
    """

    t: float
    watch_origin: float
    frame_s: float
    robots: dict[str, RobotSnapshot]
    trails: list[list[Any]]
    clients: int
    commands: list[tuple[str, bool]]
    parts: list[list[Any]]
    goals: list[list[Any]]
    cameras: list[list[Any]]
    banners: dict[str, str]


@dataclass(frozen=True)
class Hello:
    """The first message a page process gets."""

    config: PageConfig
    snapshot: Snapshot


def snapshot(
    services: Services, sessions: Mapping[str, Session], commands: Sequence[tuple[str, bool]]
) -> Snapshot:
    """The world of ``services`` as it is now; ``sessions``: the page's, by robot."""
    world = services.world
    robots = {}
    for name, state in world.robots.items():
        model = world.contacts.models.get(name)
        robots[name] = RobotSnapshot(
            robot=state.robot,
            origin=state.origin,
            limits=world.motion_limits(name),
            q=state.q,
            target=state.target,
            opening=state.opening,
            tool=state.tool,
            ghost=state.ghost,
            markers=list(state.markers),
            moving=world.moving(name),
            seconds_left=world.travels.seconds_left(state),
            speed=sessions[name].speed,
            objects=model.object_list() if model is not None else [],
            collisions=list(world.contacts.pairs.get(name, ())),
        )
    return Snapshot(
        t=world.clock.now(),
        watch_origin=services.watch.origin,
        frame_s=world.frame_s,
        robots=robots,
        trails=trail_state(services),
        clients=services.client_count,
        commands=list(commands),
        parts=part_rows(world.parts.parts.all()),
        goals=goal_rows(world.parts.goals.all()),
        cameras=camera_rows(world.cameras.all()),
        banners=fault_banners(world),
    )
