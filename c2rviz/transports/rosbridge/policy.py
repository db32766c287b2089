"""Who may open the rosbridge websocket, and the limits it keeps (pure, no I/O).

Browsers send ``Origin`` with every websocket they open and do not hold
websockets to the same-origin rule, so any web page the user visits could
drive the robot through rosbridge unless the server checks that header. A
browser's connection is let in from a loopback page (``http(s)://localhost``,
``127.0.0.1`` or ``[::1]``, any port: a roslibjs dashboard served locally) or
from an origin the user lists; a connection without ``Origin`` is not from a
browser (roslibpy, a script) and is let in. With a token set, every
connection needs ``?token=<token>`` in its URL. A host name that resolves to
127.0.0.1 is not enough (DNS rebinding): the loopback names are fixed.
"""

from __future__ import annotations

from dataclasses import dataclass

from ...errors import C2rvizError
from ...ini import LOOPBACK_HOSTS, normalize_origin, token_ok
from ...protocol.limits import below_floor, default


class PolicyError(C2rvizError):
    """A rosbridge setting that cannot work (an origin that is not one, a limit below 1)."""

    def __init__(self, name: str, value: object, expected: str) -> None:
        self.name, self.value = name, value
        shown = repr(str(value)[:60])
        super().__init__(f"rosbridge {name} {shown} is not {expected}")


@dataclass(frozen=True)
class RosbridgePolicy:
    """What the rosbridge websocket lets in, and how much.

    Attributes:
        extra_origins: Browser origins allowed besides loopback pages, e.g.
            ``https://dashboard.example.org`` (the viewer's ``--viewer-origin`` list).
        token: When set, a connection needs ``?token=<token>`` in its URL.
        max_frame_bytes: Largest frame a client may send [bytes]; a larger one
            closes the connection with code 1009 (message too big). 1 MiB holds
            a JointTrajectory of several thousand points.
        max_connections: Clients connected at once; one more is closed with
            code 1013 (try again later).
        max_subscriptions: Subscriptions (by id) per connection, and as many
            advertised topics; one more is answered with a status error.
        max_queue_length: Largest ``queue_length`` a subscription gets; a
            larger request is cut to it (with a status warning). A subscription
            without a ``throttle_rate`` is sent every message (its
            ``queue_length`` ignored, as rosbridge does) and holds this many for
            a slow reader.
        compression: Offer permessage-deflate; off by default (it costs CPU
            per subscriber and frames are small on loopback).
        max_read_ahead: Frames a connection reads ahead of the one it serves
            (websockets' ``max_queue``): past it, the server stops reading that
            connection until it catches up, so a client piling up frames while
            its service call waits holds about this many frames of memory
            (``max_frame_bytes`` each), not sixteen.
    """

    extra_origins: tuple[str, ...] = ()
    token: str | None = None
    max_frame_bytes: int = default("rosbridge", "max_frame_bytes")
    max_connections: int = default("rosbridge", "max_connections")
    max_subscriptions: int = default("rosbridge", "max_subscriptions")
    max_queue_length: int = default("rosbridge", "max_queue_length")
    compression: bool = False
    max_read_ahead: int = default("rosbridge", "max_read_ahead")

    def __post_init__(self) -> None:
        for origin in self.extra_origins:
            if normalize_origin(origin) is None:
                raise PolicyError("origin", origin, "scheme://host[:port] (http or https)")
        if self.token is not None and not (
            self.token and self.token.isascii() and self.token.isprintable()
        ):
            raise PolicyError("token", self.token, "non-empty printable ASCII")
        low = below_floor("rosbridge", self)
        if low is not None:
            name, value, floor = low
            raise PolicyError(name.replace("_", " "), value, f"at least {floor}")

    def origins(self) -> list[str]:
        """The allowed browser origins, for a refusal's message."""
        loopback = [f"http(s)://{host}:<any port>" for host in LOOPBACK_HOSTS]
        extra = sorted({o for o in map(normalize_origin, self.extra_origins) if o})
        return loopback + extra

    def origin_ok(self, origin: str | None) -> bool:
        """Whether a connection with this ``Origin`` header (None: no header) may open."""
        if origin is None:
            return True  # not a browser: browsers always send Origin on a websocket
        normal = normalize_origin(origin)
        if normal is None:
            return False
        host = normal.split("://", 1)[1].rsplit(":", 1)[0]
        if host in LOOPBACK_HOSTS:
            return True
        return normal in {normalize_origin(o) for o in self.extra_origins}

    def token_ok(self, path: str) -> bool:
        """Whether the request target ``path`` carries the token (or none is needed)."""
        return token_ok(self.token, path)
