"""The private names of viser the view uses, the check that they are all there, and the
fast sends made through them.

``view/adapter.py`` and this module are the only modules that reach inside viser; every
private name they use is listed in ``INTERNALS`` (a test checks that the list names every
private attribute used in either). ``check()`` raises
``ViserInternalsError`` if one is gone, so a viser upgrade fails loudly at start instead
of freezing the page.

The fast sends to the page: a pose (``queue_pose``, ``PoseBatch``), a GUI value
(``set_gui_value``) or a chart's data (``set_chart_data``), without viser's
``np.allclose`` per setter, without its per-array casts through typing hints and
without calling the input's own update callbacks (~0.23 ms a send instead of 1-1.9 ms;
a chart's data in ~0.05 ms instead of ~0.4 ms). A pose or a GUI value goes as a message
that puts itself on the wire (``_Orientation``, ``_Position``, ``_GuiUpdate``: viser's own
message, the same dict, without viser's walk of each field through its type hints on its
encoding thread: 0.1 us a message instead of 8.5); ``check()`` compares the two.

Functions run on the caller's thread.
"""

from __future__ import annotations

import contextlib
import dataclasses
import importlib
import logging
import time
from collections.abc import Sequence
from typing import Any

import numpy as np
import viser
from viser import _messages
from viser.infra import ClientId
from viser.infra._messages import wire_field_names

from ..errors import C2rvizError
from .door_rules import CAMERA_FIELDS, Click

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
    ("viser._messages.SetPositionMessage", ("owner",)),
    ("viser.infra._messages", ("wire_field_names",)),
    ("viser._assignable_props_api.AssignablePropsBase", ("_impl",)),
    ("viser._scene_handles._SceneNodeHandleState", ("name", "api", "position", "wxyz")),
    ("viser._scene_api.SceneApi", ("_queue_scene_message",)),
    ("viser._gui_handles._GuiHandleState", ("uuid", "gui_api", "value", "update_timestamp")),
    ("viser._gui_handles._GuiHandleState", ("props", "removed")),
    ("viser._messages.GuiUplotProps", ("data",)),
    ("viser.infra._async_message_buffer.AsyncMessageBuffer", ("message_from_id",)),
    ("viser.infra._async_message_buffer.AsyncMessageBuffer", ("message_counter",)),
    ("viser.infra._async_message_buffer.AsyncMessageBuffer", ("generator_cursors",)),
    ("viser.infra._async_message_buffer.AsyncMessageBuffer", ("id_from_redundancy_key",)),
    ("viser.infra._async_message_buffer.AsyncMessageBuffer", ("ids_from_entity_state_key",)),
    ("viser.infra._async_message_buffer.AsyncMessageBuffer", ("done",)),
    ("viser.infra._async_message_buffer.AsyncMessageBuffer", ("buffer_lock", "message_event")),
    ("viser.infra._async_message_buffer.AsyncMessageBuffer", ("atomic_counter", "event_loop")),
    ("viser.infra._infra.WebsockMessageHandler", ("get_message_buffer",)),
    ("viser.infra._infra.StateSerializer", ("_insert_message",)),
    ("server.scene", ("_owner_id", "_websock_interface")),
    ("server.scene._websock_interface", ("_record_lock", "_record_handles")),
    ("viser.ViserServer", ("_run_garbage_collector",)),
    ("viser.infra._infra", ("websockets",)),  # it starts its server with ...serve()
    ("server", ("_websock_server",)),
    ("server._websock_server", ("_broadcast_buffer", "_live_connections")),
    ("server._websock_server", ("_background_event_loop",)),
    ("server.gui", ("_websock_interface",)),
)


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
    missing += _wire_mismatches()
    read = {"ViewerCameraMessage": CAMERA_FIELDS, "SceneNodeClickMessage": Click.__struct_fields__}
    for name, fields in read.items():
        message, expected = _resolve(f"viser._messages.{name}"), set(fields) - {"type"}
        if dataclasses.is_dataclass(message) and expected != {
            f.name for f in dataclasses.fields(message) if f.init
        }:
            missing.append(f"viser._messages.{name} fields {sorted(expected)}")
    return missing


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


class _Orientation(_messages.SetOrientationMessage):
    """viser's ``SetOrientationMessage`` that puts itself on the wire at once (its fields are
    plain: a name, 4 floats, the owner): the dict and the key viser would make of it."""

    def as_serializable_dict(self, binary_buffers: Any = None) -> dict[str, Any]:
        return {"name": self.name, "wxyz": self.wxyz, "owner": self.owner, "type": _ORIENTATION}

    def redundancy_key(self) -> str:
        return f"scene:{self.name}:update:{_ORIENTATION}"


class _Position(_messages.SetPositionMessage):
    """viser's ``SetPositionMessage`` that puts itself on the wire at once (``_Orientation``)."""

    def as_serializable_dict(self, binary_buffers: Any = None) -> dict[str, Any]:
        position, owner = self.position, self.owner
        return {"name": self.name, "position": position, "owner": owner, "type": _POSITION}

    def redundancy_key(self) -> str:
        return f"scene:{self.name}:update:{_POSITION}"


class _GuiUpdate(_messages.GuiUpdateMessage):
    """viser's ``GuiUpdateMessage`` of one plain value (a float, bool or str) that puts
    itself on the wire at once (``_Orientation``; its key is viser's own)."""

    def as_serializable_dict(self, binary_buffers: Any = None) -> dict[str, Any]:
        return {"uuid": self.uuid, "updates": self.updates, "type": _GUI_UPDATE}


_ORIENTATION = _messages.SetOrientationMessage.__name__
_POSITION = _messages.SetPositionMessage.__name__
_GUI_UPDATE = _messages.GuiUpdateMessage.__name__


def _wire_mismatches() -> list[str]:
    """The fast messages whose fields, dict or key are not what viser makes of its own."""
    samples: list[tuple[Any, tuple[Any, ...]]] = [
        (_Orientation, ("/a/b", (0.5, 0.5, -0.5, 0.5))),
        (_Position, ("/a/b", (1.0, -2.0, 3.5))),
        (_GuiUpdate, ("u-1", {"value": 2.5})),
        (_GuiUpdate, ("u-2", {"value": "text"})),
    ]
    missing = []
    for fast, args in samples:
        base = fast.__mro__[1]
        ours, theirs = fast(*args), base(*args)
        if hasattr(theirs, "owner"):
            ours.owner = theirs.owner = "o"
        mine = ours.as_serializable_dict([])
        if (
            mine != theirs.as_serializable_dict([])
            or set(mine) - {"type"} != set(wire_field_names(base))
            or ours.redundancy_key() != theirs.redundancy_key()
        ):
            missing.append(f"viser._messages.{base.__name__} as c2rviz sends it")
    return missing


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
    messages: list[Any] = []
    if force or (state.position != position).any():
        state.position[:] = position
        messages.append(_Position(state.name, tuple(state.position.tolist())))
    if force or (state.wxyz != wxyz).any():
        state.wxyz[:] = wxyz
        messages.append(_Orientation(state.name, tuple(state.wxyz.tolist())))
    if messages:
        queue_updates(state.api, messages)


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
        messages: list[Any] = []
        for k in np.flatnonzero(changed[:, :3].any(axis=1)).tolist():
            state = self.states[k]
            position = poses[k, :3]
            state.position[:] = position
            messages.append(_Position(state.name, tuple(position.tolist())))
        for k in np.flatnonzero(changed[:, 3:].any(axis=1)).tolist():
            state = self.states[k]
            wxyz = poses[k, 3:]
            state.wxyz[:] = wxyz
            messages.append(_Orientation(state.name, tuple(wxyz.tolist())))
        self.sent[:] = poses
        if messages:
            queue_updates(self.states[0].api, messages)
        return len(messages)


def queue_updates(api: Any, messages: Sequence[Any]) -> None:
    """``api._queue_scene_message(m)`` for each of ``messages`` (``_Position`` and
    ``_Orientation`` of ``api``'s nodes, in order), in one pass: one lock, and viser's
    buffer kept as its ``push`` keeps it (each message under a new id, in the index of
    its node, the message it supersedes dropped), without its checks per message (some
    1.3 us a message of 2.8). A closed buffer gets viser's own ``push`` (its warning)."""
    owner = api._owner_id
    interface = api._websock_interface
    buffer = interface.get_message_buffer()
    with interface._record_lock:
        for m in messages:
            m.owner = owner
            for handle in interface._record_handles:
                handle._insert_message(m)
        if buffer.done:
            for m in messages:
                buffer.push(m)
            return
        by_id, by_key = buffer.message_from_id, buffer.id_from_redundancy_key
        by_entity = buffer.ids_from_entity_state_key
        with buffer.buffer_lock:
            for m in messages:
                key, new = m.redundancy_key(), buffer.message_counter
                by_id[new] = m
                buffer.message_counter = new + 1
                ids = by_entity.get(("scene", m.name))
                if ids is None:
                    ids = by_entity[("scene", m.name)] = set()
                ids.add(new)
                old = by_key.get(key)
                if old is not None:  # the same key: the same node's, in the same index
                    by_id.pop(old, None)
                    ids.discard(old)
                by_key[key] = new
            buffer.message_event.set()
            if buffer.atomic_counter == 0:  # else atomic_end wakes viser's loop
                with contextlib.suppress(RuntimeError):  # the loop is closed
                    buffer.event_loop.call_soon_threadsafe(buffer.message_event.set)


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
    message = _GuiUpdate(state.uuid, {"value": value})
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
