"""c2rviz's world behind the rosbridge server: the ``Bridge`` the door hands it.

What it publishes, per robot (``[NS]`` is the robot's namespace in a cell,
nothing for a robot alone; ``topics``):

=================================  ===================================  ===============
topic                              type                                 when
=================================  ===================================  ===============
``[NS]/joint_states``              ``sensor_msgs/msg/JointState``       as the arm moves
``/tf``                            ``tf2_msgs/msg/TFMessage``           as any arm moves
``/tf_static``                     ``tf2_msgs/msg/TFMessage``           latched
``[NS]/robot_description``         ``std_msgs/msg/String``              latched
``[NS]/c2rviz/events``             ``std_msgs/msg/String``              each ``watch`` event
``[NS]/visualization_marker_array`` ``visualization_msgs/msg/MarkerArray`` markers, objects
``[NS]/c2rviz/reply``              ``std_msgs/msg/String``              each command's reply
``/diagnostics``                   ``diagnostic_msgs/msg/DiagnosticArray`` faults change
``/c2rviz/cameras/NAME``           ``geometry_msgs/msg/PoseArray``      at the camera's rate
=================================  ===================================  ===============

What it takes: ``[NS]/c2rviz/command`` (``std_msgs/msg/String``, one line of
the text language; its reply on ``[NS]/c2rviz/reply``), the service
``[NS]/c2rviz/command`` (``{command}`` -> ``{reply, ok}``), ``[NS]/joint_command``
(``sensor_msgs/msg/JointState``) and ``[NS]/joint_trajectory``
(``trajectory_msgs/msg/JointTrajectory``), see ``inputs``. Each client
is a source of commands (``rosbridge HOST:PORT``) with a ``Session`` per robot
(``inputs``): it is bound to the robots it has one on, and ``fault disconnect``
on one of them closes its connection. The parameter ``robot_description`` is the (first)
robot's URDF; in a cell ``NS/robot_description`` is each robot's too.
"""

from __future__ import annotations

from collections.abc import Callable, Collection, Mapping, Sequence
from functools import partial
from typing import Any

import pinocchio as pin

from ...errors import C2rvizError
from ...ros.messages import string
from ...session.services import Services
from .bridge import TopicHub
from .inputs import CommandLines, joint_command, joint_trajectory
from .messages import (
    COMMAND_SERVICE_TYPE,
    command_request,
    command_response,
    outline,
    string_data,
)
from .messages import joint_positions as read_joint_positions
from .messages import joint_trajectory as read_joint_trajectory
from .topics import (
    DIAGNOSTIC_ARRAY,
    DIAGNOSTICS_TOPIC,
    TF_MESSAGE,
    WORLD_FRAME,
    CameraTopics,
    RobotTopics,
    namespaces,
)
from .world_feed import TF_STATIC_TOPIC, TF_TOPIC, WorldFeed

DOOR = "rosbridge"
"""How the door counts its clients among the program's (``Services.count_clients``)."""


class RobotBridge:
    """The world's robots as topics and services for ``server.RosbridgeServer``.

    Args:
        services: The program's shared parts (its world, watch hub, limits); ``shared``.
        cell: Serve each robot under its namespace (default: when there are several).
        on_quit: Called when a client sends ``quit`` (None: ``quit`` only replies).
    """

    def __init__(
        self,
        services: Services,
        *,
        cell: bool | None = None,
        on_quit: Callable[[], None] | None = None,
    ) -> None:
        self.shared = services
        world = self.world = services.world
        names = list(world.robots)
        in_cell = len(names) > 1 if cell is None else cell
        spaces = namespaces(names, in_cell)
        self.robots = {
            name: RobotTopics(name, world.state(name).robot, spaces[name], in_cell)
            for name in names
        }
        self.hub = TopicHub()
        self.feed = WorldFeed(world, self.hub, self.robots, services.watch)
        self.lines = CommandLines(services, on_quit or (lambda: None))
        self._taken: dict[str, tuple[str, str]] = {}
        self._types: list[tuple[str, str]] = [(TF_TOPIC, TF_MESSAGE), (TF_STATIC_TOPIC, TF_MESSAGE)]
        self._types.append((DIAGNOSTICS_TOPIC, DIAGNOSTIC_ARRAY))
        for topics in self.robots.values():
            self._types += topics.published()
        for name, topics in self.robots.items():
            self._types += topics.taken()
            for kind, topic in (
                ("command", topics.command),
                ("joint_command", topics.joint_command),
                ("joint_trajectory", topics.joint_trajectory),
            ):
                self._taken[topic] = (name, kind)
        self._services = {topics.command: name for name, topics in self.robots.items()}
        first = self.robots[names[0]]
        self._params: dict[str, object] = {"robot_description": first.robot.source.xml}
        if in_cell:
            for topics in self.robots.values():
                self._params[f"{topics.namespace}/robot_description"] = topics.robot.source.xml
        self._clients = 0
        self._hang_up: Callable[[str], None] = lambda source: None
        world.faults.listeners.append(self._fault)
        world.add_observers([self.feed])
        frame = first.marker_frame  # the cameras hang where the parts do (world_feed._tf)
        to_frame = pin.SE3.Identity() if frame == WORLD_FRAME else world.state(names[0]).origin
        self.cameras = CameraTopics(world, self.hub, frame, to_frame.inverse(), TF_TOPIC)
        world.add_observers([self.cameras])

    def close(self) -> None:
        """The door stops: no more messages, every session dropped."""
        if self._fault in self.world.faults.listeners:
            self.world.faults.listeners.remove(self._fault)
        if self.feed in self.world.observers:
            self.world.remove_observer(self.feed)
        self.feed.close()
        if self.cameras in self.world.observers:
            self.world.remove_observer(self.cameras)
        self.cameras.close()
        for source in {source for source, _ in self.lines.queues}:
            self.lines.closed(source)
        self._clients = 0
        self.shared.count_clients(DOOR, 0)

    # What there is.

    def topics(self) -> Sequence[tuple[str, str]]:
        return [*self._types, *self.cameras.published()]

    def services(self) -> Sequence[tuple[str, str]]:
        return [(name, COMMAND_SERVICE_TYPE) for name in self._services]

    def trajectory_joints(self) -> Mapping[str, Collection[str]]:
        return {
            topics.joint_trajectory: topics.robot.joint_names for topics in self.robots.values()
        }

    def params(self) -> Mapping[str, object]:
        return self._params

    # Clients.

    def opened(self, source: str) -> None:
        self._clients += 1
        self.shared.count_clients(DOOR, self._clients)

    def closed(self, source: str) -> None:
        self.lines.closed(source)
        self._clients = max(0, self._clients - 1)
        self.shared.count_clients(DOOR, self._clients)

    def hang_up_with(self, hang_up: Callable[[str], None]) -> None:
        self._hang_up = hang_up

    def _fault(self, robot: str, text: str) -> None:
        """``fault disconnect`` on ``robot``: the clients bound to it go (those with a session
        on it now: they sent it a command line, a service call or a joint input)."""
        if text == "fault disconnect":
            bound = {s for (s, _), q in self.lines.queues.items() if q.session.state.name == robot}
            for source in sorted(bound):
                self._hang_up(source)

    # What c2rviz publishes.

    def subscribe(self, topic: str, deliver: Callable[[dict[str, Any]], None]) -> object:
        if topic in self._taken:
            raise C2rvizError(
                f"{topic} is a topic c2rviz takes messages on, not one it publishes "
                f"(it publishes: {', '.join(self._published())})"
            )
        return self.hub.subscribe(topic, deliver)

    def unsubscribe(self, handle: object) -> None:
        self.hub.unsubscribe(handle)

    def snapshot(self, topic: str) -> dict[str, Any] | None:
        return self.hub.snapshot(topic)

    def _published(self) -> list[str]:
        return [topic for topic, _ in self._types if topic not in self._taken]

    # What c2rviz takes.

    async def publish(self, source: str, topic: str, msg: dict[str, Any]) -> None:
        entry = self._taken.get(topic)
        if entry is None:
            raise C2rvizError(
                f"{topic} is not a topic c2rviz takes messages on "
                f"(it takes: {', '.join(self._taken)})"
            )
        robot, kind = entry
        if kind == "command":
            line = self._line(string_data(msg))
            self.lines.queue(source, robot).take(line, partial(self._reply, robot))
        elif kind == "joint_command":
            joint_command(self.lines.session(source, robot), read_joint_positions(msg))
        else:
            session = self.lines.session(source, robot)
            await joint_trajectory(session, outline(msg) or read_joint_trajectory(msg))

    async def call_service(self, source: str, service: str, args: dict[str, Any]) -> dict[str, Any]:
        robot = self._services.get(service)
        if robot is None:
            raise C2rvizError(f"no service {service} (services: {', '.join(self._services)})")
        line = self._line(command_request(args))
        reply, ok = await self.lines.queue(source, robot).ask(line)
        return command_response(reply, ok)

    def _line(self, text: str) -> str:
        """One line of the text language, within the text port's length limit."""
        limit = self.shared.limits.max_line
        if len(text.encode()) > limit:
            raise C2rvizError(f"line too long (limit {limit} bytes)")
        if "\n" in text or "\r" in text:
            raise C2rvizError("one line per message: the text holds a line break")
        return text

    def _reply(self, robot: str, text: str, ok: bool) -> None:
        if text:
            self.hub.publish(self.robots[robot].reply, string(text))
