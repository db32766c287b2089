"""A viewer tab as viser's page is one, and a scene to connect it to.

``Tab`` is a websocket that speaks viser's wire format: it connects with
viser's subprotocol, sends a camera update first (viser counts a tab in after
it), sends page input (``set``) and, on a thread of its own, reads and
decodes every frame viser sends (zstd-compressed msgpack windows), so tests
can wait for what a page would have been told. ``Harness`` runs a real
``ViserScene`` on a world, with the asyncio loop driven from the test.
"""

from __future__ import annotations

import asyncio
import math
import socket
import threading
import time
from collections.abc import Callable
from typing import Any

import msgspec
import numpy as np
import viser
import zstandard
from websockets.exceptions import ConnectionClosed
from websockets.sync.client import ClientConnection, connect

from c2rviz.session import Services, SessionDefaults
from c2rviz.view.viser_scene import ViserScene
from c2rviz.world.world import World

VERSION = f"viser-v{viser.__version__}"
CAMERA = {
    "type": "ViewerCameraMessage",
    "wxyz": (1.0, 0.0, 0.0, 0.0),
    "position": (3.0, 0.0, 1.0),
    "fov": 1.0,
    "near": 0.01,
    "far": 100.0,
    "image_height": 480,
    "image_width": 640,
    "look_at": (0.0, 0.0, 0.5),
    "up_direction": (0.0, 0.0, 1.0),
}


def encode(message: Any) -> bytes:
    return msgspec.msgpack.encode(message)


def messages_in(frame: bytes | str) -> list[dict[str, Any]]:
    """The messages of one of viser's outgoing frames."""
    assert isinstance(frame, bytes)
    size = int.from_bytes(frame[:8], "little")
    compressed = int.from_bytes(frame[8:16], "little")
    inner = zstandard.ZstdDecompressor().decompress(frame[16 : 16 + compressed], size)
    return list(msgspec.msgpack.decode(inner)["messages"])


def ws_url(page_url: str) -> str:
    return page_url.replace("http://", "ws://", 1)


class Tab:
    """One page's websocket; see the module docstring.

    Attributes:
        received: Every message viser sent this tab, in order.
        closed: Set once the connection is closed.
    """

    def __init__(self, url: str, origin: str | None = None, read: bool = True) -> None:
        self.ws: ClientConnection = connect(
            ws_url(url),
            origin=origin,  # type: ignore[arg-type]
            subprotocols=[VERSION],  # type: ignore[list-item]
            open_timeout=10,
            max_size=None,
        )
        self.received: list[dict[str, Any]] = []
        self.closed = threading.Event()
        self._changed = threading.Condition()
        self.ws.send(encode(CAMERA))
        self._reader = threading.Thread(target=self._read, daemon=True)
        if read:
            self._reader.start()

    def send(self, message: Any) -> None:
        self.ws.send(message if isinstance(message, (bytes, str)) else encode(message))

    def set(self, handle: Any, value: Any) -> None:
        """What the page sends when a control is set to ``value``."""
        self.send(
            {"type": "GuiUpdateMessage", "uuid": handle._impl.uuid, "updates": {"value": value}}
        )

    def values(self, handle: Any) -> list[Any]:
        """Every value viser sent this tab for ``handle``, in order."""
        uuid = handle._impl.uuid
        with self._changed:
            return [
                m["updates"]["value"]
                for m in self.received
                if m["type"] == "GuiUpdateMessage"
                and m.get("uuid") == uuid
                and "value" in m["updates"]
            ]

    def wait(self, condition: Callable[[], bool], what: str, timeout_s: float = 60.0) -> None:
        deadline = time.monotonic() + timeout_s
        with self._changed:
            while not condition():
                left = deadline - time.monotonic()
                assert left > 0, f"timed out waiting for {what}"
                self._changed.wait(min(left, 0.05))

    def close(self) -> None:
        self.ws.close()
        if self._reader.is_alive():
            self._reader.join(timeout=10)

    def _read(self) -> None:
        try:
            while True:
                frame = self.ws.recv()
                batch = messages_in(frame)
                with self._changed:
                    self.received.extend(batch)
                    self._changed.notify_all()
        except (ConnectionClosed, OSError):
            pass
        finally:
            self.closed.set()
            with self._changed:
                self._changed.notify_all()


class Harness:
    """A real ``ViserScene``, its world and the asyncio loop they share (run from the test)."""

    def __init__(
        self,
        world: World,
        hz: float = 100.0,
        port: int = 0,
        rng: np.random.Generator | None = None,
        defaults: SessionDefaults | None = None,
        services: Services | None = None,
        **options: Any,
    ) -> None:
        self.world = world
        self.services = services or Services(
            world,
            rng=rng if rng is not None else np.random.default_rng(7),
            defaults=defaults if defaults is not None else SessionDefaults(),
        )
        self.robot = world.robot
        self.loop = asyncio.new_event_loop()
        self.scene = ViserScene(self.services, "127.0.0.1", port, hz, **options)
        self.world.add_observers([self.scene])
        self.scene.start(self.loop)
        self.panel = self.scene.panels[self.world.default]
        self.tabs: list[Tab] = []
        self.run(0.0)

    def run(self, seconds: float) -> None:
        """Let the loop run for ``seconds`` (its due sends go out)."""
        self.loop.run_until_complete(asyncio.sleep(seconds))

    def until(self, condition: Callable[[], bool], what: str, timeout_s: float = 60.0) -> None:
        """Run the loop until ``condition`` holds (a generous bound: we wait for a signal)."""
        deadline = time.monotonic() + timeout_s
        while not condition():
            assert time.monotonic() < deadline, f"timed out waiting for {what}"
            self.run(0.01)

    def tab(self, **kwargs: Any) -> Tab:
        """A page connected to the scene (closed with the harness)."""
        tab = Tab(self.scene.url, **kwargs)
        self.tabs.append(tab)
        self.until(lambda: tab.received != [], "the scene to reach the tab")
        return tab

    def call(self, fn: Callable[[], Any]) -> Any:
        """Run ``fn`` on the loop, as the world's callers do."""

        async def on_loop() -> Any:
            return fn()

        return self.loop.run_until_complete(on_loop())

    def close(self) -> None:
        for tab in self.tabs:
            tab.close()
        self.scene.stop()
        self.loop.close()


def gui_update(uuid: str, updates: dict[str, Any]) -> bytes:
    return encode({"type": "GuiUpdateMessage", "uuid": uuid, "updates": updates})


def never_reading_tab(port: int) -> socket.socket:
    """A websocket tab that opens, then reads nothing: its TCP window stays shut."""
    sock = socket.socket()
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
    sock.settimeout(10)
    sock.connect(("127.0.0.1", port))
    sock.sendall(
        (
            f"GET / HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nUpgrade: websocket\r\n"
            "Connection: Upgrade\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n"
            f"Sec-WebSocket-Version: 13\r\nSec-WebSocket-Protocol: {VERSION}\r\n\r\n"
        ).encode()
    )
    head = b""
    while b"\r\n\r\n" not in head:
        head += sock.recv(1)
    assert head.startswith(b"HTTP/1.1 101"), head
    return sock


def bad_messages(slider: str, checkbox: str) -> dict[str, bytes | str]:
    """Frames a page must not get through, aimed at the slider and the checkbox."""
    nested = {"type": "GuiUpdateMessage", "uuid": slider, "updates": {"value": 2.0}}
    return {
        "nan": gui_update(slider, {"value": math.nan}),
        "infinity": gui_update(slider, {"value": -math.inf}),
        "update_cb": gui_update(slider, {"update_cb": []}),
        "removed": gui_update(slider, {"removed": True}),
        "uuid": gui_update(slider, {"uuid": "nope"}),
        "gui_api": gui_update(slider, {"gui_api": 0}),
        "value-and-removed": gui_update(slider, {"value": 2.0, "removed": True}),
        "no-value": gui_update(slider, {}),
        "a-string": gui_update(slider, {"value": "3"}),
        "true-for-a-slider": gui_update(slider, {"value": True}),
        "a-number-for-a-checkbox": gui_update(checkbox, {"value": 1}),
        "unknown-id": gui_update("no-such-input", {"value": 1.0}),
        "a-field-of-its-own": encode({**nested, "excluded_self_client": 1}),
        "upload-start": encode(
            {
                "type": "FileTransferStartUpload",
                "source_component_uuid": slider,
                "transfer_uuid": "t1",
                "filename": "x.bin",
                "mime_type": "application/octet-stream",
                "part_count": 0,
                "size_bytes": 0,
            }
        ),
        "upload-part": encode(
            {
                "type": "FileTransferPart",
                "source_component_uuid": slider,
                "transfer_uuid": "t1",
                "part_index": 0,
                "content": b"",
            }
        ),
        "share-request": encode({"type": "ShareUrlRequest"}),
        "share-disconnect": encode({"type": "ShareUrlDisconnect"}),
        "a-server-message": encode(
            {"type": "SetPositionMessage", "name": "/frame", "position": [9.0, 9.0, 9.0]}
        ),
        "camera-nan": encode(
            {
                "type": "ViewerCameraMessage",
                "wxyz": [1.0, 0.0, 0.0, 0.0],
                "position": [math.nan, 0.0, 0.0],
                **{"fov": 1.0, "near": 0.01, "far": 100.0, "image_height": 10},
                **{"image_width": 10, "look_at": [0.0, 0.0, 0.0], "up_direction": [0, 0, 1]},
            }
        ),
        "text": "hello",
        "not-msgpack": b"\xc1\xc1\xc1",
        "many-tiny-items": b"\xdd" + (60_000).to_bytes(4, "big") + b"\x90" * 60_000,
        "many-tiny-fields": gui_update(slider, {f"k{i}": [] for i in range(5000)}),
    }
