"""What the page process is handed when it starts: how to serve the page, and the world
as it is now (``Hello``), and the ``snapshot`` that resyncs a page that fell behind; and
the cell's parts, goals, cameras and fault banners as rows, in the snapshot and the frames.

Both travel pickled inside one channel message (``page_channel``): they go once per
start of the page process (or after it fell behind), from our process to the child it
started, and they carry the robots' models and the workcell objects, which msgpack
cannot. Every frame after them is plain msgpack (``page_link``).

The command process (``page_link``) turns what the world tells it into plain rows that
msgpack carries (``part_rows``, ``goal_rows``, ``camera_rows``, ``fault_banner``); the
page process (``page_process``) turns them back into the world's own objects
(``MirrorCell``), which its ``ViserScene`` draws as the in-process page does: each part
solid with its label (held ones a little translucent), the goals' outlines, each
camera's frustum with what it sees (``cell_layers``), and a robot's
fault banner in its folder (``panel.RobotPanel.show_faults``).

Rows, not pickles: a carried part moves every frame, and 20 parts pickled cost 1.3 ms
against 30 us as rows. A held part's row says its link and offset, so the mirror moves
it with the mirror's own joint samples between two frames, as the world does.

Nothing here loads viser: the command process never does.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import pinocchio as pin

from ..collision.workcell import WorkcellObject
from ..errors import EmergencyStop
from ..motion.limits import MotionLimits
from ..robot.model import Robot
from ..session.services import Services, SessionDefaults
from ..session.session import Session
from ..world.cameras import Camera, Cameras
from ..world.part_rules import Goal
from ..world.parts import Part, Parts
from ..world.state import Marker
from ..world.world import World

RECENT_COMMANDS = 8
"""Lines the 'last commands' readout keeps: ``panel.RECENT_COMMANDS`` (not imported, as
``panel`` loads viser, which the program never needs with ``--page-process``)."""


@dataclass(frozen=True)
class PageConfig:
    """How the page process serves the page.

    Attributes:
        host, port: Where (0: a free port; on a restart, the port the tabs know).
        hz: Most sends per second [1/s].
        origins, token, max_viewers: The door's policy (``door_rules.DoorPolicy``).
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
        parts, goals, cameras: Their rows (``part_rows``, ``goal_rows``, ``camera_rows``).
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


def _flat(pose: pin.SE3) -> list[float]:
    return pose.homogeneous.ravel().tolist()  # type: ignore[no-any-return]


def _pose(flat: Sequence[float]) -> pin.SE3:
    return pin.SE3(np.asarray(flat, dtype=float).reshape(4, 4))


def part_rows(parts: Sequence[Part]) -> list[list[Any]]:
    """Each part as a row: name, shape, size, rgba, pose, kind, holder, link, offset, on,
    falling (poses flat 4x4, the world frame; ``offset`` in ``link``'s frame)."""
    return [
        [
            p.name,
            p.obj.shape,
            list(p.obj.size),
            list(p.obj.rgba),
            _flat(p.pose),
            p.kind,
            p.holder,
            p.link,
            _flat(p.offset),
            p.on,
            p.falling,
        ]
        for p in parts
    ]


def goal_rows(goals: Sequence[Goal]) -> list[list[Any]]:
    """Each goal as a row: key, pose (flat 4x4, the world frame), tolerances [m, rad]."""
    return [[g.key, _flat(g.pose), g.tol_m, g.tol_rad] for g in goals]


def camera_rows(cameras: Sequence[Camera]) -> list[list[Any]]:
    """Each camera as a row: name, pose, fields of view [rad], range [m], rate [1/s],
    noise [m, rad], blackout's end [s of the clock] (what the page draws and reads)."""
    return [
        [
            c.name,
            _flat(c.pose),
            c.h_fov_rad,
            c.v_fov_rad,
            c.range_m,
            c.rate_hz,
            c.sigma_m,
            c.sigma_rad,
            c.blackout_until,
        ]
        for c in cameras
    ]


def fault_banner(world: World, robot: str) -> str:
    """The page's banner for ``robot``'s faults (markdown; "" without any)."""
    rules = world.faults
    faults = rules.of(robot)
    stop = faults.refusal(rules.origin)
    if isinstance(stop, EmergencyStop):
        return f"**EMERGENCY STOP** — `{stop}`"  # (no emoji: a page may have no font for it)
    if stop is not None:
        return f"**PROTECTIVE STOP** — `{stop}`"
    active = [fault.text(faults.joint_names) for fault, _ in faults.active.values()]
    return "**Faults:** " + ", ".join(f"`{text}`" for text in active) if active else ""


def fault_banners(world: World) -> dict[str, str]:
    """Every robot's banner that is not empty, by name."""
    banners = {name: fault_banner(world, name) for name in world.robots}
    return {name: text for name, text in banners.items() if text}


def trail_state(services: Services) -> list[list[Any]]:
    """The robots whose trail is on, each with how often it was cleared: [name, clears]."""
    return [[name, trail.clears] for name, trail in sorted(services.trails.trails.items())]


class _Objects:
    """A robot's workcell objects in the mirror, where its collision model would be (what
    ``camera_sight.occluders`` reads: a camera's label counts what hides a part)."""

    def __init__(self, objects: Sequence[WorkcellObject]) -> None:
        self.objects = list(objects)

    def object_list(self) -> list[WorkcellObject]:
        return list(self.objects)


class MirrorCell:
    """The page process's side: the rows made into the mirror world's parts and cameras.

    Attributes:
        goals: The goals as last told (only the page reads them: no ``GoalBook`` checks).
        banners: Each robot's fault banner as last told, by name.
    """

    def __init__(self, world: World) -> None:
        self.world = world
        self.goals: list[Goal] = []
        self.banners: dict[str, str] = {}

    def parts(self, rows: Sequence[Sequence[Any]]) -> list[Part]:
        """Make the mirror's parts those of ``rows`` (a part whose shape, size and colour
        are unchanged is the same object, moved); the parts now."""
        container: Parts = self.world.parts.parts
        old = {part.name: part for part in container.clear()}
        fresh = Parts()
        for name, shape, size, rgba, pose, kind, holder, link, offset, on, falling in rows:
            part = old.get(name)
            key = (shape, tuple(size), tuple(rgba))
            if part is None or (part.obj.shape, part.obj.size, part.obj.rgba) != key:
                part = fresh.make(name, shape, size, _pose(pose), kind, rgba)
            part.pose, part.kind, part.holder, part.link = _pose(pose), kind, holder, link
            part.offset, part.on, part.falling = _pose(offset), on, falling
            container.add(part)
        return container.all()

    def set_goals(self, rows: Sequence[Sequence[Any]]) -> list[Goal]:
        """The goals of ``rows``."""
        self.goals = [Goal(key, _pose(pose), tol_m, tol_rad) for key, pose, tol_m, tol_rad in rows]
        return list(self.goals)

    def cameras(self, rows: Sequence[Sequence[Any]]) -> list[Camera]:
        """Make the mirror's cameras those of ``rows``; the cameras now."""
        cameras = Cameras()
        for name, pose, h_fov, v_fov, range_m, rate, sigma_m, sigma_rad, until in rows:
            camera = Camera(name, _pose(pose), h_fov, v_fov, range_m, rate, sigma_m, sigma_rad)
            camera.blackout_until = until
            cameras.put(camera)
        self.world.cameras = cameras
        return cameras.all()

    def objects(self, robot: str, objects: Sequence[WorkcellObject]) -> None:
        """``robot``'s workcell objects are now ``objects`` (what hides a part from a camera)."""
        self.world.contacts.models[robot] = _Objects(objects)  # type: ignore[assignment]
