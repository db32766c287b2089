"""The one shared state: the robots by name, their joints and markers, and a clock.

Every change arrives through a ``Session`` (TCP clients, the page, replays), is
checked there, and is applied here; the world then hands the effect, in SI
units, to every observer (the scene, and later recorders and watch streams)
through one fan-out. Nothing else writes the state.

Each robot has a commanded ``target`` and the ``q`` shown now; without motion
they are equal at once. ``clock`` (``world.clock``) is the time of every effect.

At its end, what a camera of the world sees now (``sight``, ``occluders``, ``seen_text``):
``cameras.py`` holds the rules (pure); these hand them the world's parts (their world
poses) and every robot's workcell objects (placed in the world) at the clock's time.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable, Iterable, Mapping, Sequence

import pinocchio as pin

from ..collision.model import CollisionModel, Pair
from ..collision.workcell import MAX_OBJECTS
from ..errors import C2rvizError, UnknownRobot
from ..motion.limits import MotionLimits, motion_limits
from ..protocol import replies
from ..robot.frames import se3_pose, se3_wxyz
from ..robot.model import Robot
from .cameras import Cameras, Occluder, PartLike, Seen, see
from .clock import Clock
from .fault_rules import FaultRules
from .grips import Grips
from .live_collisions import Contacts
from .moves import Travel, Travels
from .observer import Observer, hears
from .part_world import WorldParts
from .state import Marker, RobotState


class World:
    """Shared robot state. Used from the asyncio thread only."""

    def __init__(
        self,
        robots: Robot | Mapping[str, Robot],
        scene: Observer | None = None,
        *,
        clock: Clock | None = None,
        hz: float = 100.0,
        limits: Mapping[str, MotionLimits] | None = None,
        origins: Mapping[str, pin.SE3] | None = None,
        disabled_pairs: Mapping[str, Sequence[Pair]] | None = None,
        max_objects: int = MAX_OBJECTS,
    ) -> None:
        """Set up the world.

        Args:
            robots: One robot (named by its model), or robots by name; the first is
                the default a new session drives.
            scene: A first observer (usually the view).
            clock: The clock every part asks (default: real time).
            hz: Samples per second of a moving arm [1/s].
            limits: Motion limits by robot name (default: from each URDF).
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
        self.clock = clock if clock is not None else Clock()
        self.frame_s = 1.0 / hz
        """Time between two samples of a moving arm [s of the clock]."""
        self.contacts = Contacts(
            self.robots,
            self._tell_collisions,
            self.clock,
            self.frame_s,
            dict(disabled_pairs or {}),
            max_objects,
        )
        self.observers = [self.contacts] if scene is None else [self.contacts, scene]
        self.travels = Travels(self._show, self._rested, self.clock, self.frame_s, self._planned)
        for name, state in self.robots.items():
            self.travels.add(state, (limits or {}).get(name) or motion_limits(state.robot))
        self.grips = Grips(self._show_opening, self.clock, self.frame_s)
        """The grippers' moves (a robot's ``robot.gripper``; checked by the session)."""
        self.faults = FaultRules(self.robots, self.clock, self.travels, self._tell_fault)
        """Every robot's faults (``fault``), which every move from every door meets."""
        self.travels.rules = self.grips.rules = self.faults
        self.parts = WorldParts(self.robots, self.contacts, self.clock, self.frame_s, self._tell)
        """The parts: grasped, carried, released (``part_world.py``)."""
        self.contacts.furnish = self.parts.furnish
        self.cameras = Cameras(lambda cameras: self._tell("on_cameras", cameras))
        """The logical cameras (``cameras.py``; what one sees: ``sight`` below)."""
        self.faults.parts, self.parts.slips = self.parts, self.faults.slips  # drop, slip
        self.faults.cameras = self.cameras  # blackout

    @property
    def observers(self) -> list[Observer]:
        """Who hears the world's effects, in order (``add_observers``, ``remove_observer``;
        a new list may be assigned)."""
        return self._observers

    @observers.setter
    def observers(self, observers: list[Observer]) -> None:
        self._observers = observers
        # Those that do something with a line or its reply: most lines reach no other.
        heard = [(o, hears(o)) for o in observers]
        self._commanders = [o for o, what in heard if what in ("both", "commands")]
        self._repliers = [o for o, what in heard if what in ("both", "replies")]
        self._takers = [(o, what) for o, what in heard if what]

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

    # Motion.

    def travel(self, robot: str) -> Travel:
        """The robot's motion: its planner and who waits on it."""
        return self.travels.by_robot[robot]

    def moving(self, robot: str) -> bool:
        """The robot is travelling (a move in motion has not come to rest)."""
        return self.travels.by_robot[robot].active

    def motion_limits(self, robot: str) -> MotionLimits:
        """The robot's velocity, acceleration and jerk limits."""
        return self.travels.by_robot[robot].motion.limits

    def now(self, robot: str) -> tuple[float, ...]:
        """The robot's joints at this instant [rad or m] (mid-move too)."""
        return self.travels.now(self.robots[robot])

    # Changes: each is checked before it gets here, then told to every observer.

    def set_q(self, q: Sequence[float], robot: str | None = None, source: str = "") -> None:
        """Put a chain at ``q`` [rad or m] now, already checked against the limits.

        A move running on that robot is preempted (its waiter is told by ``source``).

        Raises:
            FaultStop: a stop holds the robot (nothing changes).
            JointStalled: a stalled joint stayed where it was (the others moved).
        """
        state = self.robots[self.default if robot is None else robot]
        faults = self.faults.robots[state.name]
        if faults.latch is not None:
            self.faults.refuse(state)
        travel = self.travels.by_robot[state.name]
        if travel.active:
            self.travels.preempt(travel, source)
        travel.synced = False
        state.target = q = tuple(q)
        if faults.held:
            self._show(state, faults.follow(q), self.clock.now())
            stalled = faults.stalled(q)
            if stalled is not None:
                raise stalled
            return
        self._show(state, q, self.clock.now())

    def _show(self, state: RobotState, q: tuple[float, ...], t: float) -> None:
        """The robot is seen at ``q`` at time ``t``: tell every observer."""
        state.q = q
        self.parts.moved(state.name, q)
        for observer in self._observers:
            observer.on_joints(state.name, q, t)

    def _show_opening(self, state: RobotState, opening: float, t: float) -> None:
        """The robot's gripper is seen at ``opening`` at time ``t``: tell every observer."""
        state.opening = opening
        for observer in self.observers:
            observer.on_gripper(state.name, opening, t)

    def _rested(self, state: RobotState, stopped: bool) -> None:
        """A move came to rest (after a stop: ``stopped``): tell every observer."""
        for observer in self.observers:
            if stopped:
                observer.on_stopped(state.name)
            else:
                observer.on_arrived(state.name)

    def _planned(self, state: RobotState, t: float) -> None:
        """The robot's motion changed at ``t``: tell every observer."""
        for observer in self.observers:
            observer.on_motion(state.name, t)

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
            placement = state.base * in_base
        px, py, pz = map(float, placement.translation)
        marker = Marker((px, py, pz), se3_wxyz(placement), rgb, shape)
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
        self.faults.refuse(self.state(robot))  # a stopped robot keeps its markers too
        self.clear_markers(robot)
        self.set_q(self.state(robot).robot.home, robot)

    def set_tool(self, robot: str, tool: pin.SE3) -> None:
        """The robot's tool point is now ``tool`` (relative to its end-effector link)."""
        state = self.state(robot)
        state.tool = tool
        for observer in self.observers:
            observer.on_tool(state.name, tool)

    def set_ghost(self, robot: str, shown: bool) -> None:
        """Show ``robot``'s ghost (its target and path while it travels) or not."""
        state = self.state(robot)
        state.ghost = shown
        for observer in self.observers:
            observer.on_ghost(state.name, shown)

    def refused(self, robot: str, source: str, line: str, error: C2rvizError) -> None:
        """``source``'s ``line`` for ``robot`` was refused with ``error``: tell the observers
        (the page shows the last error, and a guarded target in red)."""
        for observer in self.observers:
            observer.on_refused(robot, source, line, error)

    def close(self) -> None:
        """The program stops: no more frames, checks or solves."""
        self.travels.stop_all()
        self.grips.stop_all()
        self.faults.close()
        self.parts.stop()
        self.contacts.stop()

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
        if self.parts.parts:
            self.parts.objects_changed()

    def others(self, robot: str) -> list[tuple[str, CollisionModel, tuple[float, ...], pin.SE3]]:
        """Every other robot of the world as it stands: its name, collision model, joints
        [rad or m] and origin (for a robot's path checked against the rest of a cell)."""
        return [
            (name, self.collision_model(name), state.q, state.origin)
            for name, state in self.robots.items()
            if name != robot
        ]

    def _tell_fault(self, robot: str, text: str) -> None:
        for observer in list(self.observers):  # (the TCP door may close clients)
            observer.on_fault(robot, text)

    def _tell(self, method: str, *args: object) -> None:
        """Call the observers' ``method`` with ``args`` (the parts' effects)."""
        for observer in self.observers:
            getattr(observer, method)(*args)

    def _tell_collisions(self, robot: str, pairs: list[Pair]) -> None:
        for observer in self.observers:
            observer.on_collisions(robot, pairs)

    def tell_clients(self, count: int) -> None:
        """``count`` clients are connected through the doors now."""
        for observer in self.observers:
            observer.on_clients(count)

    def note(self, source: str, line: str, accepted: bool) -> None:
        """``source`` sent ``line``; tell the observers (a 'last commands' readout)."""
        for observer in self._commanders:
            observer.on_command(source, line, accepted)

    def replied(self, source: str, line: str, reply: str) -> None:
        """``source``'s ``line`` got ``reply``; tell the observers (recordings keep it)."""
        for observer in self._repliers:  # most lines: none, so this costs next to nothing
            observer.on_reply(source, line, reply)

    def taken(self, source: str, lines: Sequence[str], reply: str) -> None:
        """``source``'s ``lines`` were all taken, each answered ``reply`` (a run of ``joints``
        lines): each observer hears what ``note`` and ``replied`` per line would tell it (all
        at once through ``on_commands`` if it does nothing with replies)."""
        for observer, what in self._takers:
            if what == "both":
                for line in lines:
                    observer.on_command(source, line, True)
                    observer.on_reply(source, line, reply)
            elif what == "commands":
                observer.on_commands(source, lines)
            else:
                for line in lines:
                    observer.on_reply(source, line, reply)

    def add_observers(self, observers: Iterable[Observer]) -> None:
        self.observers = [*self._observers, *observers]

    def remove_observer(self, observer: Observer) -> None:
        observers = list(self._observers)
        observers.remove(observer)
        self.observers = observers


def occluders(world: World) -> list[Occluder]:
    """Every object of every built workcell, placed in the world frame."""
    found: list[Occluder] = []
    for name, state in world.robots.items():
        model = world.contacts.models.get(name)
        if model is None:
            continue
        for obj in model.object_list():
            found.append((obj.name, obj.shape, obj.size, state.base * obj.placement))
    return found


def sight(world: World, name: str, noisy: bool = True) -> list[Seen]:
    """What camera ``name`` sees now (raises ``UnknownCamera``); ``noisy`` False: the exact
    poses, drawing nothing from its generator (the page's look, which must not change
    what the camera reports to clients)."""
    camera = world.cameras.get(name)
    parts: list[PartLike] = [
        (p.name, p.kind or p.obj.shape, p.pose) for p in world.parts.parts.all()
    ]
    return see(camera, parts, occluders(world), world.clock.now(), noisy)


def seen_text(seen: Sequence[Seen], angle_scale: float = 1.0) -> str:
    """``p1:TYPE:x,y,z,roll,pitch,yaw;...`` (metres; angles [rad] / ``angle_scale``: a
    connection's unit), or ``none``."""
    if not seen:
        return "none"
    items = []
    for one in seen:
        x, y, z, roll, pitch, yaw = se3_pose(one.pose)
        angles = [roll / angle_scale, pitch / angle_scale, yaw / angle_scale]
        items.append(f"{one.name}:{one.kind}:{replies.numbers([x, y, z, *angles])}")
    return ";".join(items)
