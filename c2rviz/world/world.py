"""The one shared state: the robots by name, their joints and markers, and a clock.

Every change arrives through a ``Session`` (TCP clients, the page, replays), is
checked there, and is applied here; the world then hands the effect, in SI
units, to every observer (the scene, and later recorders and watch streams)
through one fan-out. Nothing else writes the state.

Each robot has a commanded ``target`` and the ``q`` shown now; without motion
they are equal at once. ``clock`` is the time base [s] of every effect.
"""

from __future__ import annotations

import asyncio
import time
from collections import deque
from collections.abc import Callable, Iterable, Mapping, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from typing import TypeVar

import numpy as np
import pinocchio as pin

from ..app.config import SessionDefaults
from ..collision.model import CollisionModel, Pair
from ..collision.workcell import MAX_OBJECTS
from ..errors import UnknownRobot
from ..ik.solver import IkSolver
from ..motion.planner import MotionLimits, motion_limits
from ..robot.model import Robot
from .effects import MAX_MARKERS, Marker, Observer
from .live_collisions import Contacts
from .moves import Travel, Travels

__all__ = ["RobotState", "World"]

T = TypeVar("T")


@dataclass(eq=False)
class RobotState:
    """One robot of the world.

    Attributes:
        name: The robot's name in this world (what ``robot NAME`` selects).
        robot: Its model and chain.
        q: The chain's values shown now [rad or m].
        target: The values it was last commanded to [rad or m].
        markers: Its markers, in the world frame, oldest first.
        origin: Where its model's root stands in the world (the cell) frame.
        port: The command port that drives it by default (None: not known here).
        tool: The tool point (TCP) relative to the end-effector link.
    """

    name: str
    robot: Robot
    q: tuple[float, ...] = ()
    target: tuple[float, ...] = ()
    markers: deque[Marker] = field(default_factory=lambda: deque(maxlen=MAX_MARKERS))
    origin: pin.SE3 = field(default_factory=pin.SE3.Identity)
    port: int | None = None
    tool: pin.SE3 = field(default_factory=pin.SE3.Identity)
    travel: Travel = field(init=False, repr=False)
    """Its motion (set by the world)."""

    def __post_init__(self) -> None:
        if not self.q:
            self.q = self.target = self.robot.home


class World:
    """Shared robot state. Used from the asyncio thread only."""

    def __init__(
        self,
        robots: Robot | Mapping[str, Robot],
        scene: Observer | None = None,
        rng: np.random.Generator | None = None,
        clock: Callable[[], float] = time.monotonic,
        hz: float = 100.0,
        limits: Mapping[str, MotionLimits] | None = None,
        defaults: SessionDefaults | None = None,
        origins: Mapping[str, pin.SE3] | None = None,
        disabled_pairs: Mapping[str, Sequence[Pair]] | None = None,
        max_objects: int = MAX_OBJECTS,
    ) -> None:
        """Set up the world.

        Args:
            robots: One robot (named by its model), or robots by name; the first is
                the default a new session drives.
            scene: A first observer (usually the view).
            rng: Random source for ``rand``.
            clock: The time base [s].
            hz: Samples per second of a moving arm [1/s].
            limits: Motion limits by robot name (default: from each URDF).
            defaults: How a new session starts (motion mode, speed).
            origins: Where each robot's root stands in the world frame (default: at
                the world's origin).
            disabled_pairs: Link pairs never checked for collision, by robot (an SRDF's).
            max_objects: Most workcell objects per robot.
        """
        named = {robots.name: robots} if isinstance(robots, Robot) else dict(robots)
        self.robots = {name: RobotState(name, robot) for name, robot in named.items()}
        for name, origin in (origins or {}).items():
            self.state(name).origin = origin
        self.default = next(iter(self.robots))
        self.contacts = Contacts(
            self.robots, self._tell_collisions, 1.0 / hz, dict(disabled_pairs or {}), max_objects
        )
        self.observers: list[Observer] = [self.contacts]
        if scene is not None:
            self.observers.append(scene)
        self.rng = rng if rng is not None else np.random.default_rng()
        self.clock = clock
        self.client_count = 0
        self.defaults = defaults if defaults is not None else SessionDefaults()
        self.travels = Travels(self._show, clock, 1.0 / hz)
        self._solvers: dict[str, IkSolver] = {}
        self._solver_thread = ThreadPoolExecutor(1, thread_name_prefix="c2rviz-ik")
        for name, state in self.robots.items():
            chosen = (limits or {}).get(name) or motion_limits(state.robot)
            state.travel = self.travels.add(state, chosen)

    def state(self, name: str | None = None) -> RobotState:
        """The robot called ``name`` (the default robot for None)."""
        try:
            return self.robots[self.default if name is None else name]
        except KeyError:
            raise UnknownRobot(str(name), list(self.robots)) from None

    # The default robot, for a one-robot world.

    @property
    def robot(self) -> Robot:
        return self.robots[self.default].robot

    @property
    def q(self) -> tuple[float, ...]:
        return self.robots[self.default].q

    @property
    def markers(self) -> deque[Marker]:
        return self.robots[self.default].markers

    # Changes: each is checked before it gets here, then told to every observer.

    def set_q(self, q: Sequence[float], robot: str | None = None, source: str = "") -> None:
        """Put a chain at ``q`` [rad or m] now, already checked against the limits.

        A move running on that robot is preempted (its waiter is told by ``source``).
        """
        state = self.robots[self.default if robot is None else robot]
        travel = state.travel
        if travel.active:
            self.travels.preempt(travel, source)
        travel.synced = False
        state.target = q = tuple(q)
        self._show(state, q, self.clock())

    def _show(self, state: RobotState, q: tuple[float, ...], t: float) -> None:
        """The robot is seen at ``q`` at time ``t``: tell every observer."""
        state.q = q
        for observer in self.observers:
            observer.on_joints(state.name, q, t)

    def ee_pose(self, robot: str | None = None) -> pin.SE3:
        """End-effector placement in the base frame, as the arm is now."""
        state = self.state(robot)
        return state.robot.ee_pose(state.q)

    def add_marker(
        self,
        pose: pin.SE3 | None,
        rgb: tuple[float, float, float],
        shape: str,
        robot: str | None = None,
        in_world: bool = False,
    ) -> Marker:
        """Drop a marker at ``pose`` in the robot's base frame (``in_world``: in the world
        frame), or at the end effector when None."""
        state = self.state(robot)
        if in_world and pose is not None:
            placement = pose
        else:
            in_base = state.robot.ee_pose(state.q) * state.tool if pose is None else pose
            placement = state.origin * state.robot.base_placement * in_base
        x, y, z, w = pin.Quaternion(placement.rotation).coeffs()
        px, py, pz = placement.translation
        marker = Marker(
            (float(px), float(py), float(pz)), (float(w), float(x), float(y), float(z)), rgb, shape
        )
        state.markers.append(marker)
        for observer in self.observers:
            observer.on_marker(state.name, marker)
        return marker

    def clear_markers(self, robot: str | None = None) -> None:
        """Remove every marker of the robot."""
        state = self.state(robot)
        state.markers.clear()
        for observer in self.observers:
            observer.on_clear_markers(state.name)

    def clear(self, robot: str | None = None) -> None:
        """Remove every marker of the robot, and home it at once."""
        self.clear_markers(robot)
        self.set_q(self.state(robot).robot.home, robot)

    def set_tool(self, robot: str, tool: pin.SE3) -> None:
        """The robot's tool point is now ``tool`` (relative to its end-effector link)."""
        state = self.state(robot)
        state.tool = tool
        for observer in self.observers:
            observer.on_tool(state.name, tool)

    # Inverse kinematics, solved off the event loop.

    def ik_solver(self, robot: str) -> IkSolver:
        """The robot's IK solver (built on first use; used on the solver thread only)."""
        solver = self._solvers.get(robot)
        if solver is None:
            solver = self._solvers[robot] = IkSolver(self.state(robot).robot)
        return solver

    def solve(self, fn: Callable[[], T]) -> asyncio.Future[T]:
        """Run ``fn`` (an IK solve or a line plan) on the one solver thread: the event loop
        goes on serving other clients meanwhile, and solves never overlap."""
        return asyncio.get_running_loop().run_in_executor(self._solver_thread, fn)

    def close(self) -> None:
        """The program stops: no more frames, checks or solves."""
        self.travels.stop_all()
        self.contacts.stop()
        self._solver_thread.shutdown(wait=False, cancel_futures=True)

    # The workcell and collisions.

    def collision_model(self, robot: str | None = None) -> CollisionModel:
        """The robot's collision model (built on first use)."""
        return self.contacts.model(self.state(robot).name)

    def edit_objects(self, robot: str, edit: Callable[[CollisionModel], object]) -> None:
        """Change ``robot``'s workcell with ``edit(model)`` (which checks its input and may
        raise, changing nothing); then tell the observers and re-check collisions."""
        model = self.collision_model(robot)
        edit(model)
        objects = model.object_list()
        for observer in self.observers:
            observer.on_objects(robot, objects)
        self.contacts.changed(robot)

    def _tell_collisions(self, robot: str, pairs: list[Pair]) -> None:
        for observer in self.observers:
            observer.on_collisions(robot, pairs)

    def set_client_count(self, count: int) -> None:
        self.client_count = count
        for observer in self.observers:
            observer.on_clients(count)

    def note(self, source: str, line: str, accepted: bool) -> None:
        """``source`` sent ``line``; tell the observers (a 'last commands' readout)."""
        for observer in self.observers:
            observer.on_command(source, line, accepted)

    def add_observers(self, observers: Iterable[Observer]) -> None:
        self.observers.extend(observers)

    def remove_observer(self, observer: Observer) -> None:
        self.observers.remove(observer)
