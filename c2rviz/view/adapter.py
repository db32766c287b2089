"""Every use of viser's private internals, reached through this one module; written for
viser 1.1.x.

viser's public API lacks four things the viewer needs, so this module (with the two
beside it that it re-exports) reaches inside viser, and no other module does:

* a door on the websocket (``start``): viser builds its websockets server on
  its own thread with fixed settings (50 MiB frames, no origin check, every
  page message applied). While viser starts, ``start`` lets viser's call of
  ``websockets.asyncio.server.serve`` through with a ``ws_guard.Door`` in front:
  origin and token checks, a frame and a client limit, a screen on every frame
  (``accept_input`` registers the inputs the page may set).
* fast sends (``queue_pose``, ``PoseBatch``, ``set_gui_value``, ``set_chart_data``,
  in ``viser_internals.py``): a pose, a slider value or a chart's data, cheaply.
* a purge of removal records (``purge_removed``): viser keeps a record of each
  removed scene node until a new tab connects.
* a stop in bounded time (``stop``), even with a tab that never reads.

``check()`` (``viser_internals.py``) looks for every private name listed in
``INTERNALS`` (a test checks that the list names every private attribute used here and
there) and raises ``ViserInternalsError`` if one is gone, so a viser
upgrade fails loudly at start instead of freezing the page. Functions run on the
caller's thread unless they say otherwise.
"""

from __future__ import annotations

import contextlib
import functools
import io
import logging
import socket
import struct
import threading
import weakref
from collections.abc import Callable, Iterator, Sequence
from typing import Any

import viser
import websockets.asyncio.server

from .door_rules import DoorPolicy

# The view's one way to viser's internals: what it needs of viser_internals, re-exported.
from .viser_internals import INTERNALS as INTERNALS
from .viser_internals import WRITTEN_FOR as WRITTEN_FOR
from .viser_internals import PoseBatch as PoseBatch
from .viser_internals import ViserInternalsError as ViserInternalsError
from .viser_internals import check as check
from .viser_internals import missing_internals as missing_internals
from .viser_internals import queue_pose as queue_pose
from .viser_internals import set_chart_data as set_chart_data
from .viser_internals import set_gui_value as set_gui_value
from .ws_guard import Door, GrabCallback, GuardedConnection, HandleCallback, InputCallback

log = logging.getLogger("c2rviz.view")

_VISER_SERVE_MODULE = "viser.infra._infra"  # where viser's websocket handler is defined

LIGHTINGS = ("studio", "plain")
"""How a page lights its scene (``start``'s ``lighting``): ``studio`` is viser's own, an
HDRI environment map, two directional lights and shadows; ``plain`` keeps the lights
without shadows and puts a white hemisphere light in place of the map. The look is nearly
the same; in software WebGL (no GPU) the map's prefiltering costs a new page about 5 s of
CPU and the shadows double each frame's cost (docs/page.md, "Lighting")."""

_doors: weakref.WeakKeyDictionary[Any, Door] = weakref.WeakKeyDictionary()
_start_lock = threading.Lock()


def start(
    host: str,
    port: int,
    *,
    label: str | None = None,
    policy: DoorPolicy | None = None,
    lighting: str = "studio",
) -> viser.ViserServer:
    """Start a viser server on ``host:port`` (0: a free port) behind a door, its scene lit
    as ``lighting`` says (one of ``LIGHTINGS``).

    Nothing goes to stdout (viser's banner is logged at debug level).

    Raises:
        ValueError: ``lighting`` is not one of ``LIGHTINGS``.
        ViserInternalsError: The installed viser lacks what the adapter uses.
    """
    if lighting not in LIGHTINGS:
        raise ValueError(f"lighting {lighting!r} is not one of {', '.join(LIGHTINGS)}")
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
    if lighting == "plain":  # intensity 2: the robots' colours as the default map gives them
        server.scene.configure_environment_map(hdri=None)
        server.scene.configure_default_lights(enabled=True, cast_shadow=False)
        server.scene.add_light_hemisphere("/lighting", intensity=2.0)
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
