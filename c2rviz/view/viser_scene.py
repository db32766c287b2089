"""The browser view: every robot of the world, their markers and a side panel, in viser.

``ViserScene`` implements ``scene.Scene`` by composing the parts of the page,
each in its own module: a ``RobotView`` per robot (``robot_view``), the
``MarkerLayer`` (``markers``), the panel (``panel``), the plots, readouts,
ghosts, history and timeline (``instruments``), the page's input
(``page_input``) and the ``SendScheduler`` (``scene_send``). viser runs behind
the door of ``adapter`` (origins, token, client and frame limits; all use of
viser's internals is there).

The world calls the scene on every accepted change, possibly hundreds of
thousands of times a second; each call only records what changed and asks for a send. A
send, at most one per frame (``1/hz``), draws the latest state: each changed robot's links
(Pinocchio FK), its target ghost and path while it moves, its panel, the markers, the
workcell objects and collisions, the trails, the parts, goals and cameras
(``cell_layers``), the plots and readouts when due; or, while the timeline looks back,
every robot as it was at that time (``scene_send``, which holds the sends). A send of many
robots comes in slices of ``scene_send.SLICE_S`` (each an atomic batch), the loop taking a
turn between them, and the scheduler paces sends by their cost (docs/page.md, "Many
robots").
"""

from __future__ import annotations

import asyncio
import errno
import logging
import socket
from collections import deque
from collections.abc import Callable, Sequence

import numpy as np
import pinocchio as pin

from ..collision.workcell import WorkcellObject
from ..errors import C2rvizError
from ..robot.visuals import LinkGeometry, load_link_geometry
from ..session.services import Services
from ..session.session import Session
from ..world.cameras import Camera
from ..world.observer import Scene
from ..world.part_rules import Goal
from ..world.parts import Part
from ..world.state import Marker
from . import adapter, scene_send
from .cell_layers import CameraLayer, PartsLayer, TrailLayer, WorkcellLayer
from .door_rules import DoorPolicy
from .handle import ToolHandles
from .instruments import Instruments
from .markers import MarkerLayer
from .page_input import PageInput
from .page_snapshot import fault_banner
from .panel import RECENT_COMMANDS, RobotPanel, StatePanel
from .robot_view import RobotView, node_name
from .scene_send import SceneSends, SendScheduler
from .timeline import Timeline

log = logging.getLogger("c2rviz.view")

STOP_TIMEOUT_S = 0.5  # longest wait for viser to stop [s]; it goes on stopping after


class ViserScene(SceneSends, Scene):
    """The viser implementation of ``scene.Scene``; see the module docstring.

    Attributes:
        world: The world shown.
        url: Where the page is served (with the token, if one is needed).
        port: The port actually bound.
        title: The page's title and panel label, ``c2rviz — <name>``.
        server: The viser server.
        views: A ``RobotView`` per robot, by the robot's name in the world.
        panels: A ``RobotPanel`` per robot, by name.
        sessions: The page's ``Session`` per robot, by name (source ``page``).
        markers: Every robot's markers.
        workcells: Each robot's workcell objects and red collisions, by name.
        trails: Every robot's trail.
        handles: A draggable handle on each robot's tool point.
        state_panel: TCP clients, last commands, the collision checkbox.
        page_input: What the page's controls run.
        scheduler: When sends go out.
    """

    def __init__(
        self,
        services: Services,
        host: str,
        port: int,
        hz: float,
        *,
        policy: DoorPolicy | None = None,
        title: str | None = None,
        port_named: bool = False,
        page_session: Callable[[Services, str], Session] | None = None,
        lighting: str = "studio",
    ) -> None:
        """Start the viser server on ``host:port`` (0 picks a free port) and draw the world.

        Args:
            services: The world to show (all of its robots), and what its page's sessions
                share with every other source.
            host: Address to serve the page on.
            port: TCP port; when it is busy viser takes the next free one, unless the
                user named it.
            hz: Most sends per second [1/s].
            policy: Who may open the page and what it may send.
            title: The cell's or robot's name (default: the robots' names).
            port_named: The user chose ``port`` (``--viser-port``, the ini): when it is
                taken the page does not move to another (``doors.open_port``'s rule).
            page_session: Makes the page's session of a robot (default: a ``Session``
                of source ``page``; the page process's hands its lines on).
            lighting: How the page lights the scene (``adapter.LIGHTINGS``).

        Raises:
            OSError: ``host`` cannot be listened on, or a named ``port`` is taken.
            adapter.ViserInternalsError: the installed viser lacks what the adapter uses.
        """
        _check_host(host)
        self.services = services
        self.world = world = services.world
        self.policy = policy if policy is not None else DoorPolicy()
        self.title = f"c2rviz — {title or ', '.join(world.robots)}"
        self.server = adapter.start(
            host, port, label=self.title, policy=self.policy, lighting=lighting
        )
        adapter.door(self.server).page_title = self.title
        self.port = self.server.get_port()
        if port_named and port not in (0, self.port):
            adapter.stop(self.server, timeout_s=STOP_TIMEOUT_S)
            raise OSError(
                errno.EADDRINUSE,
                "the port is in use; choose another with --viser-port (0 picks a free one)",
            )
        if port not in (0, self.port):
            log.warning("viewer port %d is busy; serving on %d instead", port, self.port)
        shown_host = "localhost" if host in ("0.0.0.0", "::", "") else host
        shown_host = f"[{shown_host}]" if ":" in shown_host else shown_host
        self.url = self.policy.page_url(f"http://{shown_host}:{self.port}")
        self._stopped = False
        self.slice_s = scene_send.SLICE_S  # read now: a test may set it
        self._loop: asyncio.AbstractEventLoop | None = None
        self._dirty: set[str] = set(world.robots)
        self._drawing: list[str] | None = None  # the robots the send under way has left
        self._commands: deque[tuple[str, bool]] = deque(maxlen=RECENT_COMMANDS)  # newest first
        self._client_count = services.client_count
        self._state_dirty = True
        self._objects: dict[str, Sequence[WorkcellObject]] = {}  # to draw at the next send
        self._collisions: dict[str, Sequence[tuple[str, str]]] = {}
        self._page_session = page_session or _page_session
        self.scheduler = SendScheduler(1.0 / hz, self._send)
        try:
            self._build()
        except BaseException:
            adapter.stop(self.server, timeout_s=STOP_TIMEOUT_S)
            raise

    def _build(self) -> None:
        server, world = self.server, self.world
        server.gui.configure_theme(show_share_button=False, control_width="medium")
        server.scene.add_grid("/grid", width=4.0, height=4.0, cell_size=0.25, section_size=1.0)
        geometry: dict[int, dict[str, LinkGeometry]] = {}
        segments: dict[str, str] = {}
        self.views: dict[str, RobotView] = {}
        for name, state in world.robots.items():
            segment = node_name(name)
            while segment in segments.values():  # "a b" and "a_b" draw apart
                segment += "_"
            segments[name] = segment
            if id(state.robot) not in geometry:  # the same model twice is read once
                geometry[id(state.robot)] = load_link_geometry(state.robot.source)
            shapes = geometry[id(state.robot)]
            self.views[name] = RobotView(server, name, state.robot, state.origin, shapes, segment)
        self.markers = MarkerLayer(server, segments, self._pick)
        self.workcells = {name: WorkcellLayer(server, view) for name, view in self.views.items()}
        self.trails = TrailLayer(server, segments)
        self.parts = PartsLayer(server)
        self._parts: list[Part] | None = world.parts.parts.all()  # to draw at the next send
        self._goals: list[Goal] | None = world.parts.goals.all()
        self.cameras = CameraLayer(server)
        self._cameras: list[Camera] | None = world.cameras.all()
        self.handles = ToolHandles(server, segments, self.scheduler.request)
        self._frame_camera()
        self.page_input = PageInput(server, self.markers)
        # the page's times are the watch stream's: seconds since the server started
        timeline = Timeline(server.gui, self.services.watch.origin, world.frame_s)
        self.panels: dict[str, RobotPanel] = {}
        self.sessions: dict[str, Session] = {}
        for name, state in world.robots.items():
            session = self._page_session(self.services, name)
            self.sessions[name] = session
            self.panels[name] = RobotPanel(server.gui, state, session.speed)
            self.page_input.add_robot(self.panels[name], session)
            self.handles.bind(name, session)
        velocities = self.services.defaults.motion != "off"
        self.instruments = Instruments(
            server,
            world,
            self.views,
            self.panels,
            self.markers,
            self.workcells,
            timeline,
            velocities,
        )
        self.instruments.bind(self.page_input)
        self.state_panel = StatePanel(server.gui)
        self.page_input.add_toggle(self.state_panel.collision, self._show_collision)
        for name, state in world.robots.items():
            for marker in state.markers:
                self.markers.add(name, marker)
        for name, model in world.contacts.models.items():  # a workcell set before the page
            self._objects[name] = model.object_list()
            self._collisions[name] = list(world.contacts.pairs.get(name, ()))
        self._send()

    def _frame_camera(self) -> None:
        """Aim new tabs' camera at the robots from the front right, a little above."""
        centre = np.mean([v.origin.translation for v in self.views.values()], axis=0)
        reach = max(
            float(np.linalg.norm(v.origin.translation - centre)) + v.reach()
            for v in self.views.values()
        )
        reach = max(reach, 0.5)
        look_at = centre + np.array([0.0, 0.0, 0.4 * reach])
        self.server.initial_camera.look_at = look_at
        self.server.initial_camera.position = look_at + reach * np.array([1.15, 0.9, 0.45])

    # the Observer protocol (asyncio thread, returns at once)

    def on_joints(self, robot: str, q: Sequence[float], t: float) -> None:
        self._dirty.add(robot)
        self.instruments.on_joints(robot, q, t)
        self.scheduler.request()

    def on_gripper(self, robot: str, opening: float, t: float) -> None:
        self._dirty.add(robot)
        self.scheduler.request()

    def on_marker(self, robot: str, marker: Marker) -> None:
        self.markers.add(robot, marker)
        self.instruments.on_marker(robot, marker)
        self.scheduler.request()

    def on_clear_markers(self, robot: str) -> None:
        self.markers.clear(robot)
        self.instruments.on_clear_markers(robot)
        panel = self.panels.get(robot)
        if panel is not None and panel.chosen is not None:
            panel.choose(None)
        self.scheduler.request()

    def on_clients(self, count: int) -> None:
        self._client_count = count
        self._state_dirty = True
        self.scheduler.request()

    def on_command(self, source: str, line: str, accepted: bool) -> None:
        self._commands.appendleft((line, accepted))
        self._state_dirty = True
        self.scheduler.request()

    def on_tool(self, robot: str, tool: pin.SE3) -> None:
        self._dirty.add(robot)
        self.scheduler.request()

    def on_objects(self, robot: str, objects: Sequence[WorkcellObject]) -> None:
        self._objects[robot] = list(objects)
        self.instruments.on_objects(robot, objects)
        if self.world.cameras.all():  # an object may hide a part now, or no more
            self._cameras = self.world.cameras.all()
        self.scheduler.request()

    def on_refused(self, robot: str, source: str, line: str, error: C2rvizError) -> None:
        self.instruments.on_refused(robot, line, error)
        self.scheduler.request()

    def on_ghost(self, robot: str, shown: bool) -> None:
        panel = self.panels.get(robot)
        if panel is not None:
            panel.show_ghost(shown)
        self._dirty.add(robot)
        self.scheduler.request()

    def on_collisions(self, robot: str, pairs: Sequence[tuple[str, str]]) -> None:
        self._collisions[robot] = list(pairs)
        self.scheduler.request()

    def on_fault(self, robot: str, text: str) -> None:
        self.show_faults(robot, fault_banner(self.world, robot))

    def show_faults(self, robot: str, banner: str) -> None:
        """Show ``banner`` (markdown, "" for none) as ``robot``'s fault banner (the page
        process is told the command process's, ``page_snapshot.fault_banner``)."""
        panel = self.panels.get(robot)
        if panel is not None:
            panel.show_faults(banner)
            self.scheduler.request()

    def on_parts(self, parts: Sequence[Part], t: float) -> None:
        self._parts = list(parts)
        if self.world.cameras.all():  # what the cameras see may have changed
            self._cameras = self.world.cameras.all()
        self.scheduler.request()

    def on_goals(self, goals: Sequence[Goal]) -> None:
        self._goals = list(goals)
        self.scheduler.request()

    def on_cameras(self, cameras: Sequence[Camera]) -> None:
        self._cameras = list(cameras)
        self.scheduler.request()

    def redraw(self, robot: str) -> None:
        """Draw ``robot`` at the next send (its target or motion changed)."""
        self._dirty.add(robot)
        self.scheduler.request()

    def _pick(self, robot: str, shape: str, instance: int) -> None:
        """A marker clicked in a page (viser's thread): chosen in its robot's folder."""
        self.page_input.pick(robot, shape, instance)

    # lifecycle

    def start(self, loop: asyncio.AbstractEventLoop) -> None:
        """Show the world; page input runs on ``loop``."""
        self._loop = loop
        self.page_input.start(loop)
        self.handles.start(loop)
        self.instruments.start(loop, self.scheduler.request)
        self._dirty.update(self.world.robots)
        self.scheduler.start(loop)

    def stop(self) -> None:
        """Stop the server and free its port, within ``STOP_TIMEOUT_S``; later calls do nothing."""
        if self._stopped:
            return
        self._stopped = True
        self.scheduler.stop()
        self.instruments.stop()
        self.page_input.stop()
        self.handles.stop()
        adapter.stop(self.server, timeout_s=STOP_TIMEOUT_S)

    # what tests and benchmarks read

    @property
    def sends(self) -> int:
        """Sends so far (a send draws the latest state)."""
        return self.scheduler.sends

    @property
    def sent_q(self) -> tuple[float, ...] | None:
        """The default robot's chain values [rad or m] at the latest send."""
        return self.views[self.world.default].sent_q

    @property
    def link_frames(self) -> dict[str, object]:
        """The default robot's link frames, by link name (each posed in its parent link's
        frame; ``RobotView.link_pose``: in the root's)."""
        return self.views[self.world.default].link_frames

    @property
    def marker_count(self) -> int:
        """Markers held for every robot (drawn at the next send)."""
        return self.markers.count()

    def _show_collision(self, shown: bool) -> None:
        for view in self.views.values():
            view.show_collision(shown)
        self.server.flush()


def _page_session(services: Services, robot: str) -> Session:
    """The page's session of ``robot``: source ``page``, degrees, moves that follow."""
    session = Session(services, source="page", robot=robot)
    session.set_degrees(True)
    session.set_motion("off" if services.defaults.motion == "off" else "follow")
    return session


def _check_host(host: str) -> None:
    """Raise OSError now if ``host`` cannot be bound (viser would wait forever)."""
    for family, kind, proto, _, address in socket.getaddrinfo(host, 0, type=socket.SOCK_STREAM):
        with socket.socket(family, kind, proto) as probe:
            probe.bind(address)
        return
