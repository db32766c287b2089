"""The viewer's websocket door: who may connect, and what a page may say.

viser serves the page and its websocket on one port and trusts both: any web
page the user visits may open that websocket (browsers do not hold websockets
to the same-origin rule), and viser applies whatever fields a page sends. The
adapter (``view.adapter``) puts a ``Door`` in front of viser's websocket server:

* the opening handshake (``process_request``): a websocket only from one of
  the viewer's origins (``door_rules.DoorPolicy.origins``); a request without
  ``Origin`` is not from a browser and is let on. With a token set, the
  websocket and the page both need ``?token=...``. Refused: HTTP 403.
* the page itself (``retitle``): viser's page is titled "Viser"; with
  ``page_title`` set, the page is served under that title instead.
* the connection (``handle``): the page's viser version, and at most
  ``max_clients`` tabs (one more is closed with code 1013 and a reason).
* each frame (``screen``), already bounded in size by the server
  (``max_frame_bytes``), read by ``frames``:

  - a camera update (finite) goes on to viser;
  - ``{"value": v}`` for an input the viewer registered goes to the viewer's
    callback and never to viser (which would apply and re-broadcast it); a bad
    value for it (NaN, a word, another field) to the input's ``refused``
    callback, which shows the tab the true value again;
  - a transform-controls update (finite position, unit quaternion) of a handle
    the viewer registered goes to the viewer's callback too (its drag start and
    end to its grab callback);
  - a click (finite ray) on a node the viewer made clickable goes on to viser,
    which calls the node's click callback;
  - everything else is dropped.

Every refusal is counted in ``refused`` and logged on one line, at most once a
minute per kind (per origin for origins). This module uses websockets' public
API and viser's wire format, nothing private.
"""

from __future__ import annotations

import gzip
import html
import logging
import math
import time
from collections import Counter
from collections.abc import Awaitable, Callable
from dataclasses import dataclass
from http import HTTPStatus
from typing import Any
from urllib.parse import unquote, urlsplit

from websockets.asyncio.server import ServerConnection
from websockets.exceptions import ConnectionClosed
from websockets.frames import CloseCode
from websockets.http11 import Request, Response

from ..errors import shown
from . import door_rules as frames
from .door_rules import DoorPolicy, RateLimitedLog

log = logging.getLogger("c2rviz.view")

InputCallback = Callable[[int, "bool | float | str"], None]
HandleCallback = Callable[
    [int, tuple[float, float, float, float], tuple[float, float, float]], None
]
GrabCallback = Callable[[int, bool], None]


def _is_page(path: str) -> bool:
    """Whether viser answers the request target ``path`` with the page (index.html)."""
    text = unquote(urlsplit(path).path).replace("\\", "/")
    segments = [s for s in text.split("/") if s and s != "."]
    return "/".join(segments) in ("", "index.html")


@dataclass(frozen=True)
class _Input:
    kind: type
    callback: InputCallback
    refused: Callable[[int], None] | None
    choices: frozenset[str] = frozenset()


class Door:
    """The checks in front of one viser websocket server; see the module docstring.

    Attributes:
        policy: The limits and the allowed origins.
        host: The host the viewer serves (one of its origins, unless a wildcard).
        subprotocol: The websocket subprotocol of the page served
            (``viser-v<version>``); a page of another viser version is refused.
        refused: Refusals so far, by kind: ``origin``, ``token``, ``version``,
            ``full`` (handshakes); ``frame``, ``message``, ``share``, ``upload``,
            ``input``, ``handle``, ``click``, ``oversize`` (frames); ``handler``, ``lagging``.
        connections: Every websocket being handled, admitted or being refused.
        clients: The admitted websockets, each with the door's own number.
        identify: Maps an admitted websocket to the client id handed to input
            callbacks; the adapter sets it to viser's client id.
        page_title: The page's title (its ``<title>``, the browser tab's
            name); None keeps viser's.
    """

    def __init__(
        self,
        policy: DoorPolicy,
        host: str,
        subprotocol: str,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.policy = policy
        self.subprotocol = subprotocol
        self.refused: Counter[str] = Counter()
        self.connections: set[ServerConnection] = set()
        self.clients: dict[ServerConnection, int] = {}
        self.identify: Callable[[ServerConnection], int] = lambda c: self.clients.get(c, -1)
        self._serial = 0
        self._inputs: dict[str, _Input] = {}
        self._handles: dict[str, tuple[HandleCallback, GrabCallback | None]] = {}
        self._clickable: set[str] = set()
        self.host = host
        self._log = RateLimitedLog(log, policy.log_interval_s, clock)
        self.page_title: str | None = None
        self._retitled: dict[tuple[str, bytes, str], bytes] = {}

    # what the viewer registers

    def accept_input(
        self,
        uuid: str,
        kind: type,
        callback: InputCallback,
        refused: Callable[[int], None] | None = None,
        choices: frozenset[str] = frozenset(),
    ) -> None:
        """Hand ``{"value": v}`` for ``uuid`` to ``callback(client_id, v)``.

        ``kind`` is ``bool`` (a checkbox or button: only true/false),
        ``float`` (a slider or number: any finite number, as a float) or ``str``
        (a button group: one of its ``choices``, the buttons' labels). A value
        dropped for ``uuid`` (NaN, a word, another field) goes to
        ``refused(client_id)``, so the tab can be shown the true value again.
        Both run on viser's thread and must return at once.
        """
        if kind not in (bool, float, str):
            raise TypeError(f"an input's kind is bool, float or str, not {kind!r}")
        self._inputs[uuid] = _Input(kind, callback, refused, frozenset(choices))

    def forget_input(self, uuid: str) -> None:
        self._inputs.pop(uuid, None)

    def accept_handle(
        self, name: str, callback: HandleCallback, grab: GrabCallback | None = None
    ) -> None:
        """Hand a transform-controls update of node ``name`` to ``callback``.

        ``callback(client_id, wxyz, position)`` gets a unit quaternion and a
        position [m] (finite), in the node's parent's frame; ``grab(client_id,
        held)`` is told a drag's start (True) and end (False). Both run on
        viser's thread and must return at once.
        """
        self._handles[name] = (callback, grab)

    def accept_click(self, name: str) -> None:
        """Let a click on node ``name`` (finite, an instance index or none) on to viser."""
        self._clickable.add(name)

    # the opening handshake (viser's event loop)

    def process_request(self, connection: ServerConnection, request: Request) -> Response | None:
        """Refuse a websocket from a foreign origin or without the token; None lets it on."""
        if request.headers.get("Upgrade", "").lower() != "websocket":
            if self.policy.token_ok(request.path) or not _is_page(request.path):
                return None  # no other file of viser's client build holds anything of ours
            self.refuse("token", "page", "refused the viewer page without its token")
            return connection.respond(HTTPStatus.FORBIDDEN, "open the URL c2rviz printed\n")
        origin = request.headers.get("Origin")
        port = int(connection.local_address[1])
        if origin is not None and not self.policy.origin_ok(origin, self.host, port):
            self.refuse(
                "origin",
                f"origin {origin}",
                f"refused a viewer websocket from origin {shown(origin, 80)}: allowed are "
                f"{', '.join(self.policy.origins(self.host, port))}",
            )
            return connection.respond(HTTPStatus.FORBIDDEN, "origin not allowed\n")
        if not self.policy.token_ok(request.path):
            self.refuse("token", "websocket", "refused a viewer websocket without the token")
            return connection.respond(HTTPStatus.FORBIDDEN, "token required\n")
        return None

    def retitle(self, request: Request, response: Response | None) -> Response | None:
        """viser's ``response`` to ``request``, under ``page_title`` if it is the page."""
        title = self.page_title
        if (
            title is None
            or response is None
            or response.status_code != HTTPStatus.OK
            or not _is_page(request.path)
        ):
            return response
        encoding = response.headers.get("Content-Encoding", "identity")
        key = (title, bytes(response.body or b""), encoding)
        body = self._retitled.get(key)
        if body is None:
            text = gzip.decompress(key[1]) if encoding == "gzip" else key[1]
            start, end = text.find(b"<title>"), text.find(b"</title>")
            if start < 0 or end < start:
                return response
            named = f"<title>{html.escape(title)}</title>".encode()
            text = text[:start] + named + text[end + len(b"</title>") :]
            body = gzip.compress(text) if encoding == "gzip" else text
            self._retitled.clear()  # one page, one title: nothing to keep
            self._retitled[key] = body
        headers = response.headers.copy()
        if "Content-Length" in headers:  # websockets' Headers holds every value set
            del headers["Content-Length"]
        headers["Content-Length"] = str(len(body))
        return Response(response.status_code, response.reason_phrase, headers, body)

    # the connection (viser's event loop)

    async def handle(
        self,
        connection: ServerConnection,
        inner: Callable[[ServerConnection], Awaitable[None]],
    ) -> None:
        """Check the version and the client count, then run viser's handler ``inner``."""
        self.connections.add(connection)
        try:
            if connection.subprotocol != self.subprotocol:
                got = connection.subprotocol or "no viser version"
                self.refuse(
                    "version",
                    "version",
                    f"refused a viewer page speaking {shown(got)}: this viewer speaks "
                    f"{self.subprotocol} (reload the page)",
                )
                version = self.subprotocol.removeprefix("viser-v")
                await connection.close(
                    CloseCode.PROTOCOL_ERROR,
                    f"Version mismatch. Client: {got.removeprefix('viser-v')[:20]}, "
                    f"Server: {version}",
                )
                return
            if len(self.clients) >= self.policy.max_clients:
                limit = self.policy.max_clients
                self.refuse("full", "full", f"refused a viewer tab: {limit} are connected")
                await connection.close(
                    CloseCode.TRY_AGAIN_LATER, f"viewer full: {limit} tabs open; close one"
                )
                return
            self._serial += 1
            self.clients[connection] = number = self._serial
            try:
                await inner(connection)
            except Exception as error:  # one line, not websockets' traceback per frame
                self.refuse(
                    "handler", "handler", f"viewer client {number}: {shown(repr(error), 80)}"
                )
                log.debug("viewer client %d", number, exc_info=True)
            finally:
                del self.clients[connection]
        finally:
            self.connections.discard(connection)

    # each frame (viser's event loop)

    def screen(self, connection: ServerConnection, frame: str | bytes) -> bytes | None:
        """Return a frame viser may read, or None after handling or dropping it."""
        try:
            kind = frames.read_type(frame)
            assert isinstance(frame, bytes)
            if kind == "GuiUpdateMessage":
                self._input(connection, frames.read_input(frame))
            elif kind == "TransformControlsUpdateMessage":
                self._handle(connection, frames.read_move(frame))
            elif kind in frames.GRABS:
                self._grab(connection, frames.read_grab(frame))
            elif kind == frames.CLICK:
                name = frames.read_click(frame).name
                if name in self._clickable:
                    return frame
                self._drop("click", f"a click on {shown(name)}, not one the page may click")
            elif kind in frames.REFUSED:
                self._drop(*frames.REFUSED[kind])
            elif kind != "ViewerCameraMessage":
                self._drop("message", f"a {shown(kind)} message (the viewer does not take it)")
            elif frames.camera_ok(frame):
                return frame
            else:
                self._drop("message", "a camera update that is malformed or not finite")
        except frames.Dropped as dropped:
            self._drop(dropped.kind, dropped.what)
            self._refused(connection, dropped.uuid)
        return None

    def _input(self, connection: ServerConnection, update: frames.GuiUpdate) -> None:
        target = self._inputs.get(update.uuid)
        value = update.updates.value
        if target is None:
            self._drop("input", f"a value for {shown(update.uuid)}, not one of the page's inputs")
            return
        if target.kind is bool and not isinstance(value, bool):
            self._drop("input", "a number or a word for a checkbox or button")
            self._refused(connection, update.uuid)
            return
        if target.kind is float and (isinstance(value, (bool, str)) or not math.isfinite(value)):
            shown_value = shown(value) if isinstance(value, str) else repr(value)
            self._drop("input", f"{shown_value} for a slider (a finite number is needed)")
            self._refused(connection, update.uuid)
            return
        if target.kind is str and value not in target.choices:
            self._drop("input", f"{shown(str(value))} for a button group (not one of its buttons)")
            self._refused(connection, update.uuid)
            return
        self._call(target.callback, self.identify(connection), value)

    def _refused(self, connection: ServerConnection, uuid: str | None) -> None:
        """Tell the control's owner that a value for it was dropped (if it asked)."""
        target = self._inputs.get(uuid) if uuid is not None else None
        if target is not None and target.refused is not None:
            self._call(target.refused, self.identify(connection))

    def _handle(self, connection: ServerConnection, move: frames.HandleMove) -> None:
        target = self._handles.get(move.name)
        if target is None:
            self._drop("handle", f"a drag of {shown(move.name)}, not one of the page's handles")
            return
        self._call(target[0], self.identify(connection), move.wxyz, move.position)

    def _grab(self, connection: ServerConnection, grab: frames.HandleGrab) -> None:
        target = self._handles.get(grab.name)
        if target is None:
            self._drop("handle", "a drag start or end that is not of one of the page's handles")
        elif target[1] is not None:
            held = grab.type == frames.GRABS[0]
            self._call(target[1], self.identify(connection), held)

    def _call(self, callback: Callable[..., None], *args: Any) -> None:
        try:
            callback(*args)
        except Exception as error:
            self._log.warning("callback", f"viewer callback failed: {error!r}")
            log.debug("viewer callback", exc_info=True)

    def _drop(self, kind: str, what: str) -> None:
        self.refuse(kind, kind, f"dropped {what} from a viewer page")

    def refuse(self, kind: str, key: str, message: str) -> None:
        """Count a refusal of ``kind`` and log ``message`` unless ``key`` was logged lately."""
        self.refused[kind] += 1
        self._log.warning(key, message)


class GuardedConnection(ServerConnection):
    """A viser websocket whose ``recv`` returns only frames its door let through."""

    def __init__(self, door: Door, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.door = door

    async def recv(self, decode: bool | None = None) -> Any:
        while True:
            try:
                frame = await super().recv(decode)
            except ConnectionClosed as closed:
                if closed.sent is not None and closed.sent.code == CloseCode.MESSAGE_TOO_BIG:
                    limit = self.door.policy.max_frame_bytes
                    self.door.refuse(
                        "oversize", "oversize", f"closed a viewer page: a frame over {limit} bytes"
                    )
                raise
            passed = self.door.screen(self, frame)
            if passed is not None:
                return passed
