"""Every use of viser's private internals, in one place; written for viser 1.1.x.

viser's public API lacks four things the viewer needs, so this module reaches
inside viser, and no other module does:

* a door on the websocket (``start``): viser builds its websockets server on
  its own thread with fixed settings (50 MiB frames, no origin check, every
  page message applied). While viser starts, ``start`` lets viser's call of
  ``websockets.asyncio.server.serve`` through with a ``door.Door`` in front:
  origin and token checks, a frame and a client limit, a screen on every frame
  (``accept_input`` registers the inputs the page may set).
* fast sends (``queue_pose``, ``PoseBatch``, ``set_gui_value``, ``set_chart_data``): a pose, a
  slider value or a chart's data without viser's ``np.allclose`` per setter,
  without its per-array casts through typing hints and without calling the
  input's own update callbacks (~0.23 ms a send instead of 1-1.9 ms; a chart's
  data in ~0.05 ms instead of ~0.4 ms).
* a purge of removal records (``purge_removed``): viser keeps a record of each
  removed scene node until a new tab connects.
* a stop in bounded time (``stop``), even with a tab that never reads.

``check()`` looks for every private name listed in ``INTERNALS`` (a test
checks that the list names every private attribute used here) and raises
``ViserInternalsError`` if one is gone, so a viser upgrade fails loudly at
start instead of freezing the page. Functions run on the caller's thread
unless they say otherwise.
"""

from __future__ import annotations

import contextlib
import dataclasses
import functools
import importlib
import io
import logging
import socket
import struct
import threading
import time
import weakref
from collections.abc import Callable, Iterator, Sequence
from typing import Any

import numpy as np
import viser
import websockets.asyncio.server
from viser import _messages
from viser.infra import ClientId

from ..errors import C2rvizError
from .page_messages import CAMERA_FIELDS, Click
from .policy import DoorPolicy
from .ws_guard import Door, GrabCallback, GuardedConnection, HandleCallback, InputCallback

__all__ = [
    "INTERNALS",
    "PoseBatch",
    "WRITTEN_FOR",
    "ViserInternalsError",
    "accept_click",
    "accept_handle",
    "accept_input",
    "buffered_messages",
    "check",
    "door",
    "missing_internals",
    "purge_removed",
    "queue_pose",
    "set_chart_data",
    "set_gui_value",
    "start",
    "stop",
]

log = logging.getLogger("c2rviz.view")

WRITTEN_FOR = "1.1"  # viser versions 1.1.x
# Every private name of viser used here: (where, names). check() looks in viser's
# modules and classes; start() looks at the running server ("server...").
INTERNALS: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("viser._messages", ("SetPositionMessage", "SetOrientationMessage", "GuiUpdateMessage")),
    ("viser._messages", ("ViewerCameraMessage", "TransformControlsUpdateMessage")),
    ("viser._messages.Message", ("excluded_self_client",)),
    ("viser._messages.SetPositionMessage", ("name", "position")),
    ("viser._messages.SetOrientationMessage", ("name", "wxyz")),
    ("viser._messages.GuiUpdateMessage", ("uuid", "updates")),
    ("viser._assignable_props_api.AssignablePropsBase", ("_impl",)),
    ("viser._scene_handles._SceneNodeHandleState", ("name", "api", "position", "wxyz")),
    ("viser._scene_api.SceneApi", ("_queue_scene_message",)),
    ("viser._gui_handles._GuiHandleState", ("uuid", "gui_api", "value", "update_timestamp")),
    ("viser._gui_handles._GuiHandleState", ("props", "removed")),
    ("viser._messages.GuiUplotProps", ("data",)),
    ("viser.infra._async_message_buffer.AsyncMessageBuffer", ("message_from_id",)),
    ("viser.infra._async_message_buffer.AsyncMessageBuffer", ("message_counter",)),
    ("viser.infra._async_message_buffer.AsyncMessageBuffer", ("generator_cursors",)),
    ("viser.ViserServer", ("_run_garbage_collector",)),
    ("viser.infra._infra", ("websockets",)),  # it starts its server with ...serve()
    ("server", ("_websock_server",)),
    ("server._websock_server", ("_broadcast_buffer", "_live_connections")),
    ("server._websock_server", ("_background_event_loop",)),
    ("server.gui", ("_websock_interface",)),
)
_VISER_SERVE_MODULE = "viser.infra._infra"  # where viser's websocket handler is defined

_doors: weakref.WeakKeyDictionary[Any, Door] = weakref.WeakKeyDictionary()
_start_lock = threading.Lock()


class ViserInternalsError(C2rvizError):
    """The installed viser lacks an internal the viewer uses (viser was upgraded)."""

    def __init__(self, missing: Sequence[str]) -> None:
        self.missing = tuple(missing)
        super().__init__(
            f"viser {viser.__version__} lacks what c2rviz's viewer uses: {', '.join(missing)}; "
            f"c2rviz/view/adapter.py is written for viser {WRITTEN_FOR}.x "
            f"(pip install 'viser>={WRITTEN_FOR},<1.{int(WRITTEN_FOR.split('.')[1]) + 1}')"
        )


def check() -> None:
    """Raise ``ViserInternalsError`` if a private name the adapter uses is gone."""
    missing = missing_internals()
    if missing:
        raise ViserInternalsError(missing)
    if not viser.__version__.startswith(WRITTEN_FOR + "."):
        log.warning(
            "viser %s: the view adapter is written for %s.x", viser.__version__, WRITTEN_FOR
        )


def missing_internals(server: viser.ViserServer | None = None) -> list[str]:
    """The entries of ``INTERNALS`` the installed viser lacks, as ``where.name``.

    Without ``server``, those in viser's modules and classes; with a running
    ``server``, those on it too.
    """
    missing = [
        f"{where}.{name}"
        for where, names in INTERNALS
        if server is not None or not where.startswith("server")
        for name in names
        if not _has(_resolve(where, server), name)
    ]
    read = {"ViewerCameraMessage": CAMERA_FIELDS, "SceneNodeClickMessage": Click.__struct_fields__}
    for name, fields in read.items():
        message, expected = _resolve(f"viser._messages.{name}"), set(fields) - {"type"}
        if dataclasses.is_dataclass(message) and expected != {
            f.name for f in dataclasses.fields(message) if f.init
        }:
            missing.append(f"viser._messages.{name} fields {sorted(expected)}")
    return missing


def start(
    host: str, port: int, *, label: str | None = None, policy: DoorPolicy | None = None
) -> viser.ViserServer:
    """Start a viser server on ``host:port`` (0: a free port) behind a door.

    Nothing goes to stdout (viser's banner is logged at debug level).

    Raises:
        ViserInternalsError: The installed viser lacks what the adapter uses.
    """
    check()
    the_door = Door(policy or DoorPolicy(), host, f"viser-v{viser.__version__}")
    with _start_lock, _serve_through(the_door) as calls, _quiet():
        server = viser.ViserServer(host=host, port=port, label=label, verbose=False)
    missing = [] if calls else ["its websocket server started by websockets' serve()"]
    missing += missing_internals(server)
    if missing:
        with _quiet():
            server.stop()
        raise ViserInternalsError(missing)
    the_door.identify = functools.partial(_client_id, server._websock_server)
    _doors[server] = the_door
    return server


def door(server: viser.ViserServer) -> Door:
    """The door in front of ``server`` (its refusals, clients, page URL)."""
    found = _doors.get(server)
    if found is None:
        raise ValueError("this viser server was not started by c2rviz.view.adapter.start")
    return found


def accept_input(
    server: viser.ViserServer,
    handle: Any,
    callback: InputCallback,
    refused: Callable[[int], None] | None = None,
) -> None:
    """Let the page set ``handle`` (a slider, number, checkbox, button or button group)
    through ``callback``.

    The page's ``{"value": v}`` for the handle goes to ``callback(client_id, v)``
    (viser's client id; ``v`` a float, a bool for a checkbox or button, one of
    the buttons' labels for a button group) on
    viser's thread, and nowhere else: viser neither applies it nor shows it to
    other tabs. The caller decides the true value and sends it with
    ``set_gui_value``. A value the door drops for the handle (NaN, a word) goes
    to ``refused(client_id)``. A handle not registered cannot be set from the page.
    """
    state = handle._impl
    choices: frozenset[str] = frozenset()
    if isinstance(state.value, bool):
        kind: type = bool
    elif isinstance(state.value, (int, float)):
        kind = float
    elif isinstance(state.value, str) and hasattr(handle, "options"):  # a button group
        kind, choices = str, frozenset(handle.options)
    else:
        raise TypeError(f"page input {handle.label!r} holds {type(state.value).__name__}")
    door(server).accept_input(state.uuid, kind, callback, refused, choices)


def accept_handle(
    server: viser.ViserServer,
    handle: Any,
    callback: HandleCallback,
    grab: GrabCallback | None = None,
) -> None:
    """Let the page drag ``handle`` (transform controls) through ``callback``.

    The page's update goes to ``callback(client_id, wxyz, position)`` on
    viser's thread and nowhere else: viser neither applies it nor shows it to
    other tabs; a drag's start and end go to ``grab(client_id, held)``. The
    caller decides where the handle truly stands and sends it with
    ``queue_pose``.
    """
    door(server).accept_handle(handle._impl.name, callback, grab)


def accept_click(
    server: viser.ViserServer, node: Any, callback: Callable[[int, int | None], None]
) -> None:
    """Let the page click ``node`` (a scene node): ``callback(client_id, instance_index)``.

    The door lets a well-formed click on ``node`` on to viser, which calls
    ``callback`` on its thread pool with viser's client id and the clicked
    instance of a batched node (None for a plain node).
    """
    door(server).accept_click(node._impl.name)
    node.on_click(lambda event: callback(int(event.client_id), event.instance_index))


def queue_pose(handle: Any, position: np.ndarray, wxyz: np.ndarray, force: bool = False) -> None:
    """``handle.position = position; handle.wxyz = wxyz`` for a scene node, cheaply.

    Sends only a part that changed, without viser's ``np.allclose`` per setter.

    Args:
        handle: A viser scene node handle.
        position: Its new position in its parent's frame [m], shape (3,).
        wxyz: Its new orientation, a unit quaternion (w, x, y, z), shape (4,).
        force: Send both even if unchanged (a tab shows another pose: a drag
            the server refused).
    """
    state = handle._impl
    if force or (state.position != position).any():
        state.position[:] = position
        state.api._queue_scene_message(
            _messages.SetPositionMessage(state.name, tuple(state.position.tolist()))
        )
    if force or (state.wxyz != wxyz).any():
        state.wxyz[:] = wxyz
        state.api._queue_scene_message(
            _messages.SetOrientationMessage(state.name, tuple(state.wxyz.tolist()))
        )


class PoseBatch:
    """Scene nodes posed together (a robot's link frames): ``queue_pose`` for all of them
    at once, comparing every pose with the one last sent in one array operation and
    sending only the positions and orientations that changed (exactly; a pose that
    moves by any amount is sent, so the last pose of a stopped robot always is).

    Only this batch may pose its nodes (it keeps what it sent).

    Attributes:
        handles: The nodes, in row order.
        states: Their viser states (what ``handle.position``/``wxyz`` read).
        sent: The poses last sent, one row per node (position, then w x y z).
    """

    def __init__(self, handles: Sequence[Any]) -> None:
        """``handles``: viser scene node handles, in the order of ``queue``'s rows."""
        self.handles = list(handles)
        self.states = [handle._impl for handle in self.handles]
        self.sent = np.array(
            [[*state.position, *state.wxyz] for state in self.states], dtype=float
        ).reshape(len(self.states), 7)

    def queue(self, poses: np.ndarray) -> int:
        """Pose node ``k`` at ``poses[k]``: its position [m] (3 values) then its unit
        quaternion (w, x, y, z), in its parent's frame.

        Returns:
            How many messages were queued.
        """
        changed = poses != self.sent
        sent = 0
        for k in np.flatnonzero(changed[:, :3].any(axis=1)).tolist():
            state = self.states[k]
            position = poses[k, :3]
            state.position[:] = position
            state.api._queue_scene_message(
                _messages.SetPositionMessage(state.name, tuple(position.tolist()))
            )
            sent += 1
        for k in np.flatnonzero(changed[:, 3:].any(axis=1)).tolist():
            state = self.states[k]
            wxyz = poses[k, 3:]
            state.wxyz[:] = wxyz
            state.api._queue_scene_message(
                _messages.SetOrientationMessage(state.name, tuple(wxyz.tolist()))
            )
            sent += 1
        self.sent[:] = poses
        return sent


def set_gui_value(
    handle: Any, value: float | bool | str, exclude_client: int | None = None, force: bool = False
) -> bool:
    """``handle.value = value`` without calling the handle's own update callbacks.

    Args:
        handle: A viser GUI input handle on the server's panel.
        value: Its new value (cast to the handle's type).
        exclude_client: A viser client id not to send it to (the tab that set it).
        force: Send it even if it is the value held: a tab shows another one (a
            page value that was refused, which the server never applied).

    Returns:
        Whether the value was sent.
    """
    state = handle._impl
    value = type(state.value)(value)
    if state.value == value and not force:
        return False
    message = _messages.GuiUpdateMessage(state.uuid, {"value": value})
    if exclude_client is not None:
        message.excluded_self_client = ClientId(exclude_client)
    state.gui_api._websock_interface.queue_message(message)
    state.value = value
    state.update_timestamp = time.time()
    return True


def set_chart_data(handle: Any, data: Sequence[np.ndarray]) -> None:
    """``handle.data = data`` for a uPlot chart (``gui.add_uplot``), cheaply.

    viser's setter casts each array through the prop's typing hints (some 20 µs an
    array) and compares it with the one held; this sends the arrays as they are,
    once cast to float64. The arrays are the chart's from now on: the caller
    must not change them afterwards (a new array for each update).

    Args:
        handle: A viser uPlot handle.
        data: The x values, then one array per series, all of one length.
    """
    state = handle._impl
    if state.removed:
        raise RuntimeError(f"Cannot assign to 'data' on a removed {type(handle).__name__}.")
    arrays = tuple(np.asarray(column, dtype=np.float64) for column in data)
    state.props.data = arrays
    state.gui_api._websock_interface.queue_message(
        _messages.GuiUpdateMessage(state.uuid, {"data": arrays})
    )


def buffered_messages(server: viser.ViserServer) -> int:
    """Messages in viser's broadcast buffer (what a new tab is sent)."""
    return len(server._websock_server._broadcast_buffer.message_from_id)


def purge_removed(server: viser.ViserServer, max_lag: int = 50_000) -> int:
    """Drop the records of removed scene nodes that every tab has read.

    viser's own purge, which it runs only when a tab connects. A tab that reads
    nothing holds the records back; one ``max_lag`` messages behind is
    disconnected (it reconnects and is sent the scene afresh).

    Returns:
        How many messages left the buffer.
    """
    websock = server._websock_server
    buffer = websock._broadcast_buffer
    before = len(buffer.message_from_id)
    server._run_garbage_collector()
    head = buffer.message_counter - 1
    late = [
        cid for cid, cursor in dict(buffer.generator_cursors).items() if head - cursor > max_lag
    ]
    connections = [websock._live_connections.get(cid) for cid in late]
    if late:
        door(server).refuse("lagging", "lagging", f"dropped {len(late)} viewer tab(s) not reading")
        _on_loop(websock._background_event_loop, _abort, [c for c in connections if c])
    return before - len(buffer.message_from_id)


def stop(server: viser.ViserServer, timeout_s: float = 2.0) -> bool:
    """Stop ``server`` and free its port, waiting at most ``timeout_s`` [s].

    Open websockets are cut first (a tab that never reads would hold viser's
    own stop for 6 s); viser's stop then runs on a helper thread.

    Returns:
        Whether viser stopped within ``timeout_s``; if not, it goes on stopping.
    """
    websock = server._websock_server
    found = _doors.pop(server, None)
    cut = list(found.connections) if found else list(websock._live_connections.values())
    _on_loop(websock._background_event_loop, _abort, cut)
    stopper = threading.Thread(target=server.stop, name="viser-stop", daemon=True)
    with _quiet():
        stopper.start()
        stopper.join(timeout_s)
    if stopper.is_alive():
        log.warning("viser did not stop within %g s; it goes on stopping", timeout_s)
        return False
    return True


def _abort(connections: Sequence[Any]) -> None:
    """Cut ``connections`` at once (on viser's loop), dropping what they have not read.

    A linger time of zero makes the kernel reset the TCP connection instead of
    keeping it (and the port) to deliver data the tab is not reading.
    """
    for connection in connections:
        transport = getattr(connection, "transport", None)
        if transport is None:
            continue
        sock = transport.get_extra_info("socket")
        if sock is not None:
            with contextlib.suppress(OSError):
                sock.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
        transport.abort()


def _on_loop(loop: Any, fn: Callable[..., None], *args: Any) -> None:
    with contextlib.suppress(RuntimeError):  # the loop is closed: nothing to do
        loop.call_soon_threadsafe(fn, *args)


def _client_id(websock: Any, connection: Any) -> int:
    """viser's client id of ``connection``, or -1."""
    for client_id, live in list(websock._live_connections.items()):
        if live is connection:
            return int(client_id)
    return -1


@contextlib.contextmanager
def _serve_through(door: Door) -> Iterator[list[int]]:
    """Put ``door`` in front of viser's websocket server while viser starts.

    viser calls ``websockets.asyncio.server.serve`` on its own thread (once per
    port it tries) before ``ViserServer()`` returns; calls made by anyone else
    pass unchanged. Yields the ports viser tried through the door.
    """
    module = websockets.asyncio.server
    original = module.serve
    calls: list[int] = []

    def serve(handler: Any, host: Any = None, port: Any = None, **kwargs: Any) -> Any:
        if getattr(handler, "__module__", None) != _VISER_SERVE_MODULE:
            return original(handler, host, port, **kwargs)
        calls.append(port)
        viser_request = kwargs.get("process_request")

        def process_request(connection: Any, request: Any) -> Any:
            refused = door.process_request(connection, request)
            if refused is not None or viser_request is None:
                return refused
            return door.retitle(request, viser_request(connection, request))

        async def guarded(connection: Any) -> None:
            await door.handle(connection, handler)

        kwargs.update(
            process_request=process_request,
            max_size=door.policy.max_frame_bytes,
            max_queue=door.policy.max_queued_frames,
            create_connection=functools.partial(GuardedConnection, door),
        )
        return original(guarded, host, port, **kwargs)

    module.serve = serve  # type: ignore[assignment,misc]
    try:
        yield calls
    finally:
        module.serve = original  # type: ignore[misc]


@contextlib.contextmanager
def _quiet() -> Iterator[None]:
    """Keep viser's prints (banner, 'Server stopped') off stdout."""
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        yield
    if out.getvalue().strip():
        log.debug("viser: %s", out.getvalue().strip())


def _resolve(where: str, server: Any = None) -> Any:
    """The object named ``where`` (``viser.x.Y`` or ``server.a.b``), or None."""
    parts = where.split(".")
    if parts[0] == "server":
        found = server
        for name in parts[1:]:
            found = getattr(found, name, None)
        return found
    for cut in range(len(parts), 0, -1):
        try:
            found = importlib.import_module(".".join(parts[:cut]))
        except ImportError:
            continue
        for name in parts[cut:]:
            found = getattr(found, name, None)
        return found
    return None


def _has(owner: Any, name: str) -> bool:
    """Whether ``owner`` has ``name``: an attribute, a dataclass field or an annotation."""
    if owner is None:
        return False
    if hasattr(owner, name):
        return True
    if dataclasses.is_dataclass(owner) and name in {f.name for f in dataclasses.fields(owner)}:
        return True
    return any(name in getattr(k, "__annotations__", {}) for k in getattr(owner, "__mro__", ()))
