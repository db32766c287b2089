"""Browser origins, as the doors that browsers reach check them (pure, standard library).

Browsers send ``Origin`` with every websocket they open and do not hold websockets to the
same-origin rule, so the page's door (``view.door_rules``) and rosbridge's
(``transports.rosbridge.policy``) both compare it with the origins they allow, spelled
one way by ``normalize_origin``, and both read a URL's token with ``token_ok``. A host
name that resolves to 127.0.0.1 is not enough (DNS rebinding): the loopback names are fixed.
"""

from __future__ import annotations

import hmac
from urllib.parse import parse_qs, urlsplit

__all__ = ["LOOPBACK_HOSTS", "normalize_origin", "token_ok"]

LOOPBACK_HOSTS = ("localhost", "127.0.0.1", "[::1]")


def normalize_origin(origin: str) -> str | None:
    """``scheme://host:port`` in lower case with the port spelled out, or None.

    None for anything but an ``http``/``https`` origin (``null``, a path, ...).
    """
    try:
        parts = urlsplit(origin.strip())
        port = parts.port
    except ValueError:
        return None
    if (
        parts.scheme not in ("http", "https")
        or not parts.hostname
        or parts.path not in ("", "/")
        or parts.query
        or parts.fragment
        or "@" in parts.netloc
    ):
        return None
    host = f"[{parts.hostname}]" if ":" in parts.hostname else parts.hostname
    return f"{parts.scheme}://{host}:{port or (443 if parts.scheme == 'https' else 80)}"


def token_ok(token: str | None, path: str) -> bool:
    """Whether the request target ``path`` carries ``?token=<token>`` (None: none is needed).

    Any ``token`` value in the query may match; each is compared in constant time.
    """
    if token is None:
        return True
    given = parse_qs(urlsplit(path).query, keep_blank_values=True).get("token", [])
    return any(hmac.compare_digest(g.encode(), token.encode()) for g in given)
