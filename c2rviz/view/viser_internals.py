"""The private names of viser the view uses, and the check that they are all there.

``view/adapter.py`` and ``view/viser_sends.py`` are the only modules that reach inside
viser; every private name they use is listed in ``INTERNALS`` (a test checks that the
list names every private attribute used in either). ``check()`` raises
``ViserInternalsError`` if one is gone, so a viser upgrade fails loudly at start instead
of freezing the page.
"""

from __future__ import annotations

import dataclasses
import importlib
import logging
from collections.abc import Sequence
from typing import Any

import viser

from ..errors import C2rvizError
from .page_messages import CAMERA_FIELDS, Click

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
