"""Fast sends to the page through viser's internals: a pose (``queue_pose``, ``PoseBatch``),
a GUI value (``set_gui_value``) or a chart's data (``set_chart_data``), without viser's
``np.allclose`` per setter, without its per-array casts through typing hints and
without calling the input's own update callbacks (~0.23 ms a send instead of 1-1.9 ms;
a chart's data in ~0.05 ms instead of ~0.4 ms).

Every private name used here is in ``viser_internals.INTERNALS``. Functions run on the
caller's thread.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from typing import Any

import numpy as np
from viser import _messages
from viser.infra import ClientId


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
