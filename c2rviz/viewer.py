"""The browser view: a viser server that draws the robot, its markers and a side panel.

``ViserScene`` implements the ``Scene`` protocol. The world calls it on every
accepted command, possibly hundreds of thousands of times a second, so each
call only records the new state and schedules a send on the asyncio loop: at
most one send per period (``1/hz``), the latest state wins, and a lone command
after a quiet spell goes out at once. A send runs Pinocchio forward kinematics
on the viewer's own ``Data`` and poses one viser frame per link (Pinocchio is
the one source of kinematic truth); each link's URDF geometry hangs below its
frame at its URDF origin.

The panel's sliders follow the commanded joints and, when dragged, command the
world themselves (through the asyncio loop, so TCP clients see the change with
``where``). viser's public share-link tunnel is disabled: no share button, and
a share request sent by a page is refused.
"""

from __future__ import annotations

import asyncio
import contextlib
import io
import logging
import math
import re
import socket
import time
from collections import deque
from collections.abc import Iterator, Sequence
from typing import Any

import numpy as np
import pinocchio as pin
import viser
from viser import _messages as viser_messages

from .errors import C2rvizError
from .robot import Robot
from .scene import MAX_MARKERS, Marker, Scene
from .session import Session
from .visuals import Shape, load_link_geometry
from .world import World

__all__ = ["ViserScene"]

log = logging.getLogger("c2rviz.viewer")

RECENT_COMMANDS = 8  # lines kept for the 'last commands' readout
MARKER_SIZE_M = 0.03
SHOWN_LINE_CHARS = 80


class ViserScene(Scene):
    """The viser implementation of ``scene.Scene``; see the module docstring.

    Attributes:
        url: Where the page is served, with the port actually bound.
        server: The viser server.
        link_frames: The viser frame of each link (Pinocchio body frame), by name.
        sends: How many sends have gone out (a send draws the latest state).
        sent_q: The joint values [rad or m] of the latest send.
        refused_share_requests: Share-link requests refused so far.
    """

    def __init__(self, robot: Robot, host: str, port: int, hz: float) -> None:
        """Start the viser server on ``host:port`` (0 picks a free port).

        Args:
            robot: The robot to draw.
            host: Address to serve the page on.
            port: TCP port; when it is busy viser takes the next free one.
            hz: Most sends per second [1/s].

        Raises:
            OSError: ``host`` cannot be listened on.
        """
        _check_host(host)
        self.robot = robot
        self.period_s = 1.0 / hz
        self._data = robot.model.createData()  # the world's robot.data is not ours
        self._session: Session | None = None  # the page's way in, once started
        self._loop: asyncio.AbstractEventLoop | None = None
        self._timer: asyncio.Handle | None = None
        self._last_send_s = -math.inf
        self._stopped = False
        self._q: tuple[float, ...] = robot.home
        self._q_dirty = True
        self._new_markers: deque[Marker] = deque(maxlen=MAX_MARKERS)
        self._clear_markers = False
        self._marker_handles: deque[Any] = deque()
        self._marker_count = 0
        self._commands: deque[str] = deque(maxlen=RECENT_COMMANDS)  # newest last
        self._client_count = 0
        self._panel_dirty = True
        # Per joint: serial of the latest slider value the page sent, and of
        # the latest one applied to the world; they differ while one is in
        # flight, and the slider is then left alone (no tug of war with a drag).
        self._page_serial = [0] * robot.n
        self._applied_serial = [0] * robot.n
        self.sends = 0
        self.sent_q: tuple[float, ...] | None = None
        self.refused_share_requests = 0

        with _quiet():
            self.server = viser.ViserServer(host=host, port=port, label=robot.name, verbose=False)
        self._refuse_share_links()
        bound = self.server.get_port()
        if port not in (0, bound):
            log.warning("viewer port %d is busy; serving on %d instead", port, bound)
        shown_host = "localhost" if host in ("0.0.0.0", "::", "") else host
        shown_host = f"[{shown_host}]" if ":" in shown_host else shown_host
        self.url = f"http://{shown_host}:{bound}"
        self._build_scene()
        self._build_panel()
        self._send()

    # the Observer protocol (asyncio thread, returns at once)

    def on_joints(self, robot: str, q: Sequence[float], t: float) -> None:
        self._q = tuple(q)
        self._q_dirty = True
        self._schedule()

    def on_marker(self, robot: str, marker: Marker) -> None:
        self._new_markers.append(marker)
        self._schedule()

    def on_clear_markers(self, robot: str) -> None:
        self._new_markers.clear()
        self._clear_markers = True
        self._schedule()

    def on_clients(self, count: int) -> None:
        self._client_count = count
        self._panel_dirty = True
        self._schedule()

    def on_command(self, source: str, line: str, accepted: bool) -> None:
        self._commands.append(line if accepted else f"{line}  [refused]")
        self._panel_dirty = True
        self._schedule()

    @property
    def marker_count(self) -> int:
        """Markers drawn at the latest send."""
        return len(self._marker_handles)

    # lifecycle

    def start(self, world: World, loop: asyncio.AbstractEventLoop) -> None:
        """Show ``world``; the page acts on it as the source ``page``, through ``loop``."""
        self._session = Session(world, source="page")
        self._session.set_degrees(True)
        self._loop = loop
        self._q = world.q
        self._q_dirty = True
        self._schedule()

    def stop(self) -> None:
        """Stop the server and free its port; later calls do nothing."""
        if self._stopped:
            return
        self._stopped = True
        if self._timer is not None:
            self._timer.cancel()
            self._timer = None
        with _quiet():
            self.server.stop()

    # sending

    def _schedule(self) -> None:
        """Send now if the last send is a period old, else once it is; never twice."""
        loop = self._loop
        if self._timer is not None or loop is None or self._stopped:
            return
        due = self._last_send_s + self.period_s
        if loop.time() >= due:
            self._timer = loop.call_soon(self._send)
        else:
            self._timer = loop.call_at(due, self._send)

    def _send(self) -> None:
        """Draw whatever changed since the last send, in one atomic batch."""
        self._timer = None
        if self._stopped:
            return
        if self._loop is not None:
            self._last_send_s = self._loop.time()
        with self.server.atomic():
            if self._q_dirty:
                self._q_dirty = False
                self._draw_robot(self._q)
                self._sync_sliders(self._q)
                self.sent_q = self._q
            if self._clear_markers or self._new_markers:
                self._draw_markers()
            if self._panel_dirty:
                self._panel_dirty = False
                self._clients.value = str(self._client_count)
                self._recent.value = "\n".join(_shown(line) for line in self._commands)
        self.server.flush()
        self.sends += 1

    def _draw_robot(self, q: Sequence[float]) -> None:
        """Pose every link frame from Pinocchio FK and update the pose readout."""
        model, data = self.robot.model, self._data
        pin.forwardKinematics(model, data, self.robot.configuration(q))
        pin.updateFramePlacements(model, data)
        for frame_id, handle in self._link_frames:
            # What ``handle.position = ...`` / ``handle.wxyz = ...`` send, without their
            # np.allclose change test (~15 us each, two per link per send).
            placement = data.oMf[frame_id]
            state = handle._impl
            position = placement.translation
            if (state.position != position).any():
                state.position[:] = position
                state.api._queue_scene_message(
                    viser_messages.SetPositionMessage(state.name, tuple(position.tolist()))
                )
            wxyz = _wxyz(placement.rotation)
            if (state.wxyz != wxyz).any():
                state.wxyz[:] = wxyz
                state.api._queue_scene_message(
                    viser_messages.SetOrientationMessage(state.name, tuple(wxyz.tolist()))
                )
        ee = self.robot.base_placement.actInv(data.oMf[self.robot.ee_frame])
        # round() then + 0.0: no "-0.0" in the readout
        x, y, z = (round(float(v), 3) + 0.0 for v in ee.translation)
        roll, pitch, yaw = (
            round(float(v), 1) + 0.0 for v in np.degrees(pin.rpy.matrixToRpy(ee.rotation))
        )
        self._ee_pose.value = (
            f"x {x:+.3f}  y {y:+.3f}  z {z:+.3f} m\nR {roll:+.1f}  P {pitch:+.1f}  Y {yaw:+.1f} deg"
        )

    def _sync_sliders(self, q: Sequence[float]) -> None:
        """Move each slider to the commanded value, unless the page is moving it.

        This is ``slider.value = shown`` without its call of our on_update callback:
        the callback is async, so viser would hand it to its own thread
        (run_coroutine_threadsafe: a wake-up and a task per slider per send) only for
        it to ignore an update that came from us.
        """
        for i, (slider, value) in enumerate(zip(self._sliders, q)):
            if self._page_serial[i] != self._applied_serial[i]:
                continue
            shown = self._to_slider(i, value)
            state = slider._impl
            current = state.value
            # A NaN or a non-number a page sent is replaced too.
            if not (isinstance(current, (int, float)) and abs(current - shown) <= 1e-9):
                state.gui_api._websock_interface.queue_message(
                    viser_messages.GuiUpdateMessage(state.uuid, {"value": shown})
                )
                state.value = shown
                state.update_timestamp = time.time()

    def _draw_markers(self) -> None:
        if self._clear_markers:
            self._clear_markers = False
            while self._marker_handles:
                self._marker_handles.popleft().remove()
        for marker in self._new_markers:
            self._marker_handles.append(self._add_marker_node(marker))
            if len(self._marker_handles) > MAX_MARKERS:
                self._marker_handles.popleft().remove()
        self._new_markers.clear()

    def _add_marker_node(self, marker: Marker) -> Any:
        self._marker_count += 1
        name = f"/markers/m{self._marker_count}"
        pose: dict[str, Any] = {"position": marker.position, "wxyz": marker.wxyz}
        scene, size, rgb = self.server.scene, MARKER_SIZE_M, marker.rgb
        if marker.shape == "cube":
            return scene.add_box(name, color=rgb, dimensions=(size,) * 3, **pose)
        if marker.shape == "cylinder":
            return scene.add_cylinder(name, radius=size / 3, height=size, color=rgb, **pose)
        if marker.shape == "arrow":  # along the marker's x axis, as in RViz
            points = np.array([[[0.0, 0.0, 0.0], [1.7 * size, 0.0, 0.0]]])
            return scene.add_arrows(
                name,
                points,
                colors=rgb,
                shaft_radius=size / 8,
                head_radius=size / 3,
                head_length=size / 2,
                **pose,
            )
        return scene.add_icosphere(name, radius=size / 2, color=rgb, **pose)

    # building the page

    def _build_scene(self) -> None:
        robot, scene = self.robot, self.server.scene
        self.server.gui.configure_theme(show_share_button=False, control_width="medium")
        scene.add_grid("/grid", width=4.0, height=4.0, cell_size=0.25, section_size=1.0)
        base = robot.base_placement
        scene.add_frame(
            "/base",
            axes_length=0.25,
            axes_radius=0.008,
            position=base.translation,
            wxyz=_wxyz(base.rotation),
        )
        geometry = load_link_geometry(robot.source)
        self._collision_nodes: list[Any] = []
        self._link_frames: list[tuple[int, Any]] = []
        self.link_frames: dict[str, Any] = {}
        for link in robot.link_names():
            node = f"/robot/{_node_name(link)}"
            handle = scene.add_frame(node, show_axes=False)
            self._link_frames.append((robot.model.getFrameId(link, pin.BODY), handle))
            self.link_frames[link] = handle
            shapes = geometry.get(link)
            if shapes is None:
                continue
            for k, shape in enumerate(shapes.visual):
                self._add_shape(f"{node}/visual_{k}", shape, visible=True)
            for k, shape in enumerate(shapes.collision):
                self._collision_nodes.append(
                    self._add_shape(f"{node}/collision_{k}", shape, visible=False)
                )
        scene.add_frame(
            f"/robot/{_node_name(robot.eelink)}/ee", axes_length=0.12, axes_radius=0.005
        )
        self._frame_camera()

    def _frame_camera(self) -> None:
        """Aim new tabs' camera at the robot from the front right, a little above."""
        pin.framesForwardKinematics(self.robot.model, self._data, self.robot.neutral)
        reach = max((float(np.linalg.norm(f.translation)) for f in self._data.oMf), default=1.0)
        reach = max(reach, 0.5)
        look_at = np.array([0.0, 0.0, 0.4 * reach])
        self.server.initial_camera.look_at = look_at
        self.server.initial_camera.position = look_at + reach * np.array([1.15, 0.9, 0.45])

    def _add_shape(self, name: str, shape: Shape, visible: bool) -> Any:
        scene = self.server.scene
        position = shape.origin[:3, 3]
        wxyz = _wxyz(shape.origin[:3, :3])
        common: dict[str, Any] = {"position": position, "wxyz": wxyz, "visible": visible}
        if shape.rgba is None:  # a mesh with colours of its own
            assert shape.mesh is not None
            return scene.add_mesh_trimesh(name, shape.mesh, **common)
        rgb, alpha = shape.rgba[:3], shape.rgba[3]
        common["opacity"] = None if alpha >= 1.0 else alpha
        if shape.kind == "box":
            sx, sy, sz = shape.size
            return scene.add_box(name, color=rgb, dimensions=(sx, sy, sz), **common)
        if shape.kind == "cylinder":
            radius, length = shape.size
            return scene.add_cylinder(name, radius=radius, height=length, color=rgb, **common)
        if shape.kind == "sphere":
            return scene.add_icosphere(name, radius=shape.size[0], color=rgb, **common)
        assert shape.mesh is not None
        return scene.add_mesh_simple(
            name, shape.mesh.vertices, shape.mesh.faces, color=rgb, **common
        )

    def _build_panel(self) -> None:
        gui = self.server.gui
        self._sliders: list[Any] = []
        self._ranges: list[tuple[float, float]] = []
        with gui.add_folder("Joints"):
            for i, joint in enumerate(self.robot.joints):
                if joint.prismatic:
                    low, high, step, unit = joint.lower, joint.upper, 0.001, "m"
                elif joint.continuous:
                    low, high, step, unit = -180.0, 180.0, 0.1, "deg"
                else:
                    low, high = math.degrees(joint.lower), math.degrees(joint.upper)
                    step, unit = 0.1, "deg"
                # Round the ends inward to a step: "-180.000421" reads badly, and the
                # slider cannot pass a limit (values shown are clamped to the ends).
                low = round(math.ceil(low / step - 1e-9) * step, 6)
                high = round(math.floor(high / step + 1e-9) * step, 6)
                self._ranges.append((low, high))
                slider = gui.add_slider(
                    joint.name,
                    min=low,
                    max=high,
                    step=step,
                    initial_value=self._to_slider(i, self._q[i]),
                    hint=f"joint {i} [{unit}]",
                )
                slider.on_update(self._slider_callback(i))
                self._sliders.append(slider)
            home = gui.add_button("Home", hint="all joints to zero (home)")
            home.on_click(self._button_callback("home"))
            random = gui.add_button("Random", hint="every joint to a random value")
            random.on_click(self._button_callback("rand"))
        collision = gui.add_checkbox("Show collision geometry", False)
        collision.on_update(self._collision_callback)
        with gui.add_folder("State"):
            # Typed Any: mypy reads viser's GuiTextHandle.value as read-only, though it is not.
            self._ee_pose: Any = gui.add_text(
                "End effector",
                "",
                multiline=True,
                disabled=True,
                hint=f"{self.robot.eelink} in {self.robot.base} frame",
            )
            self._clients: Any = gui.add_text("TCP clients", "0", disabled=True)
            self._recent: Any = gui.add_text("Last commands", "", multiline=True, disabled=True)

    # page input (viser's thread), handed to the asyncio loop

    def _slider_callback(self, index: int) -> Any:
        async def moved(event: viser.GuiEvent) -> None:
            if event.client is None or self._loop is None:
                return  # our own update of the slider (or nothing to command yet)
            value = event.target.value
            self._page_serial[index] += 1
            serial = self._page_serial[index]
            self._loop.call_soon_threadsafe(self._slider_moved, index, value, serial)

        return moved

    def _slider_moved(self, index: int, value: object, serial: int) -> None:
        """A page moved slider ``index`` to ``value`` (slider units): command the world
        through the page's session, as ``move index value`` in degrees (metres for a
        prismatic joint); a refused value sends the slider back to the true value."""
        self._applied_serial[index] = serial
        text = repr(float(value)) if isinstance(value, (int, float)) else "?"  # NaN: 'nan'
        self._page_line(f"move {index} {text}")

    def _page_line(self, line: str) -> None:
        session = self._session
        if session is None or self._stopped:
            return
        try:
            session.run(line)
        except C2rvizError as exc:
            log.warning("refused from the page: %s: %s", line, exc)
            self._q_dirty = True  # the sliders go back to the true values
            self._schedule()

    def _button_callback(self, line: str) -> Any:
        async def clicked(event: viser.GuiEvent) -> None:
            if self._loop is not None:
                self._loop.call_soon_threadsafe(self._page_line, line)

        return clicked

    async def _collision_callback(self, event: viser.GuiEvent) -> None:
        for node in self._collision_nodes:
            node.visible = bool(event.target.value)
        self.server.flush()

    def _to_slider(self, index: int, value: float) -> float:
        """Joint value [rad or m] in slider units (deg or m), within the slider's range."""
        joint = self.robot.joints[index]
        shown = float(value) if joint.prismatic else math.degrees(value)
        if joint.continuous:
            shown = (shown + 180.0) % 360.0 - 180.0
        if index < len(self._ranges):
            low, high = self._ranges[index]
            shown = min(max(shown, low), high)
        return round(shown, 6)  # 30, not 29.999999999999996 (which the page shows as "30.0")

    # the share-link tunnel stays off

    def _refuse_share_links(self) -> None:
        """Replace viser's share-link handlers: a page cannot open a public tunnel."""
        websock = self.server._websock_server
        for message in (viser_messages.ShareUrlRequest, viser_messages.ShareUrlDisconnect):
            with contextlib.suppress(AssertionError, KeyError):
                websock.unregister_handler(message)
        websock.register_handler(viser_messages.ShareUrlRequest, self._refuse_share)

    def _refuse_share(self, client_id: int, message: Any) -> None:
        self.refused_share_requests += 1
        log.warning(
            "refused a share-link request from viewer client %d: the public tunnel is disabled",
            client_id,
        )


def _check_host(host: str) -> None:
    """Raise OSError now if ``host`` cannot be bound (viser would wait forever)."""
    for family, kind, proto, _, address in socket.getaddrinfo(host, 0, type=socket.SOCK_STREAM):
        with socket.socket(family, kind, proto) as probe:
            probe.bind(address)
        return


@contextlib.contextmanager
def _quiet() -> Iterator[None]:
    """Keep viser's banner off stdout (the cli prints the URL itself)."""
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        yield
    if out.getvalue().strip():
        log.debug("viser: %s", out.getvalue().strip())


def _wxyz(rotation: np.ndarray) -> np.ndarray:
    x, y, z, w = pin.Quaternion(rotation).coeffs()
    return np.array([w, x, y, z])


def _node_name(link: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]", "_", link)


def _shown(line: str) -> str:
    line = line.replace("\r", " ").replace("\t", " ")
    return line if len(line) <= SHOWN_LINE_CHARS else line[: SHOWN_LINE_CHARS - 3] + "..."
