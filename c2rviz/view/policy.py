"""What the viewer's websocket lets in: origins, a token and limits (pure, no I/O).

Browsers send ``Origin`` with every websocket they open and do not hold
websockets to the same-origin rule, so any page the user visits can open the
viewer's websocket unless the server checks that header. The viewer's own
origins are ``http://`` on a loopback name (``localhost``, ``127.0.0.1``,
``[::1]``) or on the host it serves, at the port the request came in on; a
reverse proxy's origin is added by the user. A host name that resolves to
127.0.0.1 is not enough (DNS rebinding): the names are fixed.
"""

from __future__ import annotations

from dataclasses import dataclass
from urllib.parse import quote

from ..errors import C2rvizError, shown
from ..ini import LOOPBACK_HOSTS, normalize_origin, token_ok
from ..protocol.limits import below_floor, default, default_s

__all__ = ["LOOPBACK_HOSTS", "DoorPolicy", "DoorPolicyError", "normalize_origin"]

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
