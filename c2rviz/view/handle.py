"""A draggable handle on each robot's tool point: dragging it moves the arm by IK.

Each robot has one transform-controls node (viser's gizmo, ``/handles/<name>``,
posed in the world frame) at its tool point: ``origin * base_placement *
ee_pose(q) * tool``. It follows the arm at every send, except while a tab
holds it (between viser's drag start and end, that tab still connected) or
a drag of it waits or is being solved.

A drag goes through the one way in: the door (``adapter.accept_handle``)
hands the page's pose to a callback on viser's thread, which records the
newest pose per robot and, if none was waiting, asks the asyncio loop to run
it. There it becomes ``moveto x,y,z,roll,pitch,yaw`` (the tool pose in the
robot's base frame [m], degrees: the page session's units) on that robot's
page session. A drag the session refuses (unreachable, guard) is logged
(rate-limited) and the handle is put back at the true tool pose in every tab.
"""

from __future__ import annotations

import asyncio
import contextlib
import functools
import logging
import math
from collections.abc import Awaitable, Callable
from typing import Any

import pinocchio as pin
import viser

from ..errors import C2rvizError
from ..protocol import replies
from ..robot.frames import in_base, se3_pose, wxyz_se3
from ..session.session import Session
from ..world.state import RobotState
from . import adapter
from .door_rules import RateLimitedLog
from .page_input import Handoff

log = logging.getLogger("c2rviz.view")

HANDLE_SCALE = 0.2  # the gizmo's size [m]
DEGREE = math.pi / 180.0  # [rad]: the page sessions' angle unit

Pose = tuple[tuple[float, float, float, float], tuple[float, float, float]]


def moveto_line(state: RobotState, in_world: pin.SE3, angle_scale: float = DEGREE) -> str:
    """The ``moveto`` line that puts the robot's tool at ``in_world`` (world frame).

    Args:
        state: The robot.
        in_world: The tool pose in the world frame.
        angle_scale: The session's angle unit in [rad] (``Session.angle_scale``).

    Returns:
        ``moveto x,y,z,roll,pitch,yaw``: the pose in the robot's base frame [m].
    """
    x, y, z, roll, pitch, yaw = se3_pose(in_base(state.base, in_world))
    angles = [roll / angle_scale, pitch / angle_scale, yaw / angle_scale]
    return f"moveto {replies.numbers([x, y, z, *angles])}"


class ToolHandles:
    """Every robot's tool handle; see the module docstring.

    Attributes:
        nodes: The transform-controls node per robot, by the robot's name.
        refused: Drags the sessions refused so far.
    """

    def __init__(
        self, server: viser.ViserServer, segments: dict[str, str], request: Callable[[], None]
    ) -> None:
        """Add a handle per robot.

        Args:
            server: The viser server.
            segments: Each robot's node name segment, by the robot's name.
            request: Asks for a send (which calls ``draw`` for ``due`` robots).
        """
        self._server = server
        self._request = request
        self._loop: asyncio.AbstractEventLoop | None = None
        self._handoff: Handoff[str, tuple[int, Pose]] = Handoff(self._run)
        self._running: set[str] = set()
        self._stale: set[str] = set()  # put back at the tool pose at the next send
        self._due: set[str] = set()  # drawn at the next send
        self._held: dict[str, int] = {}  # the client holding each held handle (under the lock)
        self._log = RateLimitedLog(log)
        self.refused = 0
        self.nodes: dict[str, Any] = {}
        for name, segment in segments.items():
            node = server.scene.add_transform_controls(f"/handles/{segment}", scale=HANDLE_SCALE)
            self.nodes[name] = node
            adapter.accept_handle(
                server,
                node,
                functools.partial(self._arrived, name),
                functools.partial(self._grabbed, name),
            )
        self._sessions: dict[str, Session] = {}

    def bind(self, name: str, session: Session) -> None:
        """Run robot ``name``'s drags on ``session`` (the page's session of that robot)."""
        self._sessions[name] = session

    def start(self, loop: asyncio.AbstractEventLoop) -> None:
        """Run drags on ``loop`` from now on (earlier drags are dropped)."""
        self._loop = loop
        self._handoff.start(loop)

    def stop(self) -> None:
        """Drop drags from now on."""
        self._loop = None
        self._handoff.stop()

    def busy(self, name: str) -> bool:
        """Whether robot ``name``'s handle is held by a tab, or a drag of it waits or runs."""
        with self._handoff.lock:
            client = self._held.get(name)
            if client is not None and client not in self._server.get_clients():
                self._held.pop(name, None)  # the tab closed mid-drag
                client = None
        return client is not None or self._handoff.waiting(name) or name in self._running

    def draw(self, state: RobotState, ee: pin.SE3 | None = None) -> None:
        """Put the robot's handle at its tool point, unless a drag of it is under way.

        ``ee`` is the end effector's placement in the base frame at ``state.q`` if known
        (the view's FK of this frame), else it is computed."""
        name = state.name
        if self.busy(name):
            return
        force = name in self._stale
        self._stale.discard(name)
        self._due.discard(name)
        robot = state.robot
        if ee is None:
            ee = robot.ee_pose(state.q)
        tool = state.origin * robot.base_placement * ee * state.tool
        pose = pin.SE3ToXYZQUAT(tool)  # x y z, then the quaternion as x y z w
        adapter.queue_pose(self.nodes[name], pose[:3], pose[[6, 3, 4, 5]], force)

    def due(self) -> set[str]:
        """The robots whose handle a drag left to be drawn (put back, or after a move)."""
        return set(self._due)

    # viser's thread: record, and wake the loop once

    def _arrived(self, name: str, client: int, quaternion: Any, position: Any) -> None:
        self._handoff.put(name, (client, (quaternion, position)))

    def _grabbed(self, name: str, client: int, held: bool) -> None:
        with self._handoff.lock:
            if held:
                self._held[name] = client
                return
            if self._held.get(name) == client:
                self._held.pop(name, None)
        loop = self._loop
        if loop is not None:
            with contextlib.suppress(RuntimeError):
                loop.call_soon_threadsafe(self._released, name)

    # the asyncio thread

    def _released(self, name: str) -> None:
        self._due.add(name)
        self._request()

    def _run(self, name: str, drag: tuple[int, Pose]) -> None:
        if name in self._running:  # the drag in flight runs the newest when it is done
            self._handoff.defer(name, drag)
            return
        _, (wxyz_now, position) = drag
        session = self._sessions.get(name)
        if session is None or self._loop is None:
            return
        in_world = wxyz_se3(position, wxyz_now)
        line = moveto_line(session.state, in_world, session.angle_scale)
        try:
            reply = session.run(line)
        except C2rvizError as exc:
            self._refuse(name, line, exc)
            self._done(name)
            return
        if not isinstance(reply, Awaitable):
            self._done(name)
            return
        self._running.add(name)
        future = asyncio.ensure_future(reply)
        future.add_done_callback(functools.partial(self._answered, name, line))

    def _answered(self, name: str, line: str, future: asyncio.Future[Any]) -> None:
        self._running.discard(name)
        error = None if future.cancelled() else future.exception()
        if isinstance(error, C2rvizError):
            self._refuse(name, line, error)
        elif error is not None:
            self._log.warning("handle", f"a drag failed: {line}: {error!r}")
            self._stale.add(name)
        self._done(name)

    def _refuse(self, name: str, line: str, error: C2rvizError) -> None:
        self.refused += 1
        self._log.warning("refused", f"refused a drag from the page: {line}: {error}")
        self._stale.add(name)

    def _done(self, name: str) -> None:
        """Run the newest drag that came meanwhile, or put the handle back (a send)."""
        newer = self._handoff.take(name)
        if newer is not None:
            self._stale.discard(name)  # a newer drag: the page shows that one
            self._run(name, newer)
        else:
            self._due.add(name)
            self._request()
