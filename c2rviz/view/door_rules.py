"""The rules of the viewer's websocket door (pure, no I/O): who it lets in (origins, a
token and limits: ``DoorPolicy``), what a page may say (the few viser client messages the
door reads, decoded strictly), and how often a stranger's misdeeds are logged
(``RateLimitedLog``).

Browsers send ``Origin`` with every websocket they open and do not hold
websockets to the same-origin rule, so any page the user visits can open the
viewer's websocket unless the server checks that header. The viewer's own
origins are ``http://`` on a loopback name (``localhost``, ``127.0.0.1``,
``[::1]``) or on the host it serves, at the port the request came in on; a
reverse proxy's origin is added by the user. A host name that resolves to
127.0.0.1 is not enough (DNS rebinding): the names are fixed.

Each message reader takes one websocket frame (msgpack, viser's wire format) and
returns the message, or raises ``Dropped`` saying what kind of frame it was
and why it is not taken: an unknown field, a number that is not finite, a
quaternion that is not a unit one. Nothing here knows who registered what;
that is the door's.

Warnings that a stranger can trigger come at most one line per kind per interval. A
page, or anything else that can reach the viewer's port, can send bad frames as fast as
it likes; each one must not cost a log line (let alone a traceback). ``RateLimitedLog``
lets the first warning of a kind through, holds back the rest for ``interval_s`` and
says, on the next line of that kind, how many it held back.
"""

from __future__ import annotations

import logging
import math
import time
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass
from urllib.parse import quote

import msgspec

from ..errors import C2rvizError, shown
from ..ini import LOOPBACK_HOSTS, normalize_origin, token_ok
from ..protocol.limits import below_floor, default, default_s

WILDCARD_HOSTS = ("", "0.0.0.0", "::", "[::]")


class DoorPolicyError(C2rvizError):
    """A door setting that cannot work (an origin that is not an origin, ...)."""

    def __init__(self, name: str, value: object, expected: str) -> None:
        self.name, self.value = name, value
        super().__init__(f"viewer {name} {shown(str(value))} is not {expected}")


@dataclass(frozen=True)
class DoorPolicy:
    """What the viewer's websocket lets in.

    Attributes:
        extra_origins: Origins allowed besides the viewer's own, e.g.
            ``https://robot.example.org`` for a reverse proxy.
        token: When set, the page and its websocket need ``?token=<token>``.
        max_clients: Tabs connected at once.
        max_frame_bytes: Largest frame a page may send [bytes]; the page's
            own messages (a camera update, a slider value) are under 1 KiB.
        max_queued_frames: Received frames held per tab before reading stops.
        log_interval_s: Shortest time between two log lines of one kind [s].
    """

    extra_origins: tuple[str, ...] = ()
    token: str | None = None
    max_clients: int = default("page", "max_clients")
    max_frame_bytes: int = default("page", "max_frame_bytes")
    max_queued_frames: int = default("page", "max_queued_frames")
    log_interval_s: float = default_s("page", "log_interval_s")

    def __post_init__(self) -> None:
        for origin in self.extra_origins:
            if normalize_origin(origin) is None:
                raise DoorPolicyError("origin", origin, "scheme://host[:port] (http or https)")
        if self.token is not None and not (self.token.isascii() and self.token.isprintable()):
            raise DoorPolicyError("token", self.token, "printable ASCII")
        low = below_floor("page", self)
        if low is not None:
            name, value, floor = low
            raise DoorPolicyError(name.replace("_", " "), value, f"at least {floor}")

    def origins(self, host: str, port: int) -> list[str]:
        """The origins allowed for a viewer served on ``host`` reached at ``port``."""
        hosts = set(LOOPBACK_HOSTS)
        spelled = f"[{host}]" if ":" in host and not host.startswith("[") else host
        served = normalize_origin(f"http://{spelled}")
        if host not in WILDCARD_HOSTS and served is not None:
            hosts.add(served[len("http://") : served.rindex(":")])
        extra = (normalize_origin(o) for o in self.extra_origins)
        return sorted({f"http://{h}:{port}" for h in hosts} | {o for o in extra if o})

    def origin_ok(self, origin: str, host: str, port: int) -> bool:
        """Whether a websocket from ``origin`` may reach a viewer on ``host`` at ``port``."""
        return normalize_origin(origin) in self.origins(host, port)

    def token_ok(self, path: str) -> bool:
        """Whether the request target ``path`` carries the token (or none is needed)."""
        return token_ok(self.token, path)

    def page_url(self, base_url: str) -> str:
        """The URL to print for the page at ``base_url`` (``http://host:port``).

        With a token, the page's own URL carries it, and so does the websocket
        URL the page is told to use: viser's page drops its own query string
        when it makes the websocket URL, but takes one from ``websocket=``.
        """
        if self.token is None:
            return base_url
        base = base_url.rstrip("/")
        socket_url = base.replace("http://", "ws://", 1).replace("https://", "wss://", 1)
        ask = f"?token={quote(self.token, safe='')}"
        return f"{base}/{ask}&websocket={quote(socket_url + '/' + ask, safe=':/')}"


UNIT_TOLERANCE = 1e-3  # how far a handle's quaternion's norm may be from 1
MAX_INSTANCE = 1 << 31  # an instance index of a batched node is below this
GRABS = ("TransformControlsDragStartMessage", "TransformControlsDragEndMessage")
CLICK = "SceneNodeClickMessage"

# Messages a page of this viser version sends but the viewer refuses: (kind, what).
REFUSED = {
    "ShareUrlRequest": ("share", "a share-link request (the public tunnel is disabled)"),
    "ShareUrlDisconnect": ("share", "a share-link request (the public tunnel is disabled)"),
    "FileTransferStartUpload": ("upload", "a file upload (the viewer takes none)"),
    "FileTransferPart": ("upload", "a file upload (the viewer takes none)"),
}


class Dropped(Exception):
    """A frame the door does not take: ``kind`` counts it, ``what`` says it in a log line,
    ``uuid`` names the control it was meant for, when it could be read."""

    def __init__(self, kind: str, what: str, uuid: str | None = None) -> None:
        super().__init__(what)
        self.kind = kind
        self.what = what
        self.uuid = uuid


class _Envelope(msgspec.Struct):
    type: str


class _Value(msgspec.Struct, forbid_unknown_fields=True):
    value: bool | float | str


class GuiUpdate(msgspec.Struct, forbid_unknown_fields=True):
    type: str
    uuid: str
    updates: _Value


class _AnyUpdate(msgspec.Struct):
    uuid: str


class HandleMove(msgspec.Struct, forbid_unknown_fields=True):
    type: str
    name: str
    wxyz: tuple[float, float, float, float]
    position: tuple[float, float, float]
    owner: str = ""


class HandleGrab(msgspec.Struct, forbid_unknown_fields=True):
    type: str
    name: str
    owner: str = ""


class Click(msgspec.Struct, forbid_unknown_fields=True):
    type: str
    name: str
    instance_index: int | None
    ray_origin: tuple[float, float, float]
    ray_direction: tuple[float, float, float]
    screen_pos: tuple[float, float]
    modifier: str | None = None
    owner: str = ""


class _Camera(msgspec.Struct, forbid_unknown_fields=True):
    type: str
    wxyz: tuple[float, float, float, float]
    position: tuple[float, float, float]
    fov: float
    near: float
    far: float
    image_height: int
    image_width: int
    look_at: tuple[float, float, float]
    up_direction: tuple[float, float, float]


CAMERA_FIELDS = tuple(f for f in _Camera.__struct_fields__ if f != "type")
_ENVELOPE = msgspec.msgpack.Decoder(_Envelope)
_GUI_UPDATE = msgspec.msgpack.Decoder(GuiUpdate)
_ANY_UPDATE = msgspec.msgpack.Decoder(_AnyUpdate)
_CAMERA = msgspec.msgpack.Decoder(_Camera)
_HANDLE_MOVE = msgspec.msgpack.Decoder(HandleMove)
_HANDLE_GRAB = msgspec.msgpack.Decoder(HandleGrab)
_CLICK = msgspec.msgpack.Decoder(Click)


def read_type(frame: str | bytes) -> str:
    """The message type of ``frame``."""
    if isinstance(frame, str):
        raise Dropped("frame", "a text frame")
    try:
        return _ENVELOPE.decode(frame).type
    except msgspec.MsgspecError:
        raise Dropped("frame", "a frame that is not a viser message") from None


def read_input(frame: bytes) -> GuiUpdate:
    """A ``{"value": v}`` update of a control (v a number, true/false or a button's label)."""
    try:
        return _GUI_UPDATE.decode(frame)
    except msgspec.MsgspecError:
        try:
            uuid: str | None = _ANY_UPDATE.decode(frame).uuid
        except msgspec.MsgspecError:
            uuid = None
        raise Dropped(
            "input", "an input update other than {'value': a number, true/false or a label}", uuid
        ) from None


def read_move(frame: bytes) -> HandleMove:
    """A transform-controls drag to a finite position and a unit quaternion."""
    try:
        move = _HANDLE_MOVE.decode(frame)
    except msgspec.MsgspecError:
        raise Dropped("handle", "a malformed transform-controls update") from None
    if not all(map(math.isfinite, (*move.wxyz, *move.position))):
        raise Dropped("handle", "a drag to a pose that is not finite")
    if abs(math.sqrt(sum(c * c for c in move.wxyz)) - 1.0) > UNIT_TOLERANCE:
        raise Dropped("handle", "a drag to an orientation that is not a unit quaternion")
    return move


def read_grab(frame: bytes) -> HandleGrab:
    """A transform-controls drag's start or end."""
    try:
        return _HANDLE_GRAB.decode(frame)
    except msgspec.MsgspecError:
        raise Dropped("handle", "a malformed drag start or end") from None


def read_click(frame: bytes) -> Click:
    """A click on a scene node: finite ray and screen point, an instance index or none."""
    try:
        click = _CLICK.decode(frame)
    except msgspec.MsgspecError:
        raise Dropped("click", "a malformed click") from None
    numbers = (*click.ray_origin, *click.ray_direction, *click.screen_pos)
    if not all(map(math.isfinite, numbers)):
        raise Dropped("click", "a click with a ray that is not finite")
    index = click.instance_index
    if index is not None and not 0 <= index < MAX_INSTANCE:
        raise Dropped("click", f"a click on instance {index}")
    return click


def camera_ok(frame: bytes) -> bool:
    """Whether ``frame`` is a well-formed, finite camera update."""
    try:
        c = _CAMERA.decode(frame)
    except msgspec.MsgspecError:
        return False
    numbers = (*c.wxyz, *c.position, c.fov, c.near, c.far, *c.look_at, *c.up_direction)
    return all(map(math.isfinite, numbers))


class RateLimitedLog:
    """At most one warning per key per ``interval_s``; held-back ones are counted.

    Attributes:
        interval_s: Shortest time between two lines of one key [s].
        max_keys: Keys remembered at most; keys are often made from what a
            stranger sent (an origin), so the table must not grow without bound.
    """

    def __init__(
        self,
        logger: logging.Logger,
        interval_s: float = 60.0,
        clock: Callable[[], float] = time.monotonic,
        max_keys: int = 1024,
    ) -> None:
        self.logger = logger
        self.interval_s = interval_s
        self.max_keys = max_keys
        self._clock = clock
        self._last_s: dict[str, float] = {}
        self._held: Counter[str] = Counter()

    def warning(self, key: str, message: str) -> bool:
        """Log ``message`` unless a line of ``key`` went out within the interval.

        Returns:
            Whether the line was logged.
        """
        now = self._clock()
        last = self._last_s.get(key)
        if last is not None and now - last < self.interval_s:
            self._held[key] += 1
            return False
        if last is None and len(self._last_s) >= self.max_keys:
            self._forget(now)
        held = self._held.pop(key, 0)
        self._last_s[key] = now
        if held:
            message += f" ({held} more like it held back in the last {self.interval_s:g} s)"
        self.logger.warning("%s", message)
        return True

    def _forget(self, now: float) -> None:
        """Drop keys whose interval is over; if none is, drop them all."""
        stale = [k for k, t in self._last_s.items() if now - t >= self.interval_s]
        for key in stale or list(self._last_s):
            del self._last_s[key]
            self._held.pop(key, None)
