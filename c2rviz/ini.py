"""Reading ``cmdinterpreter.ini``: where it is, its text, and its numbers; and the browser
origins the doors that browsers reach allow (pure, standard library).

The server's settings (``app.config``) and the clients (``clients.connection``) both
read the ini; this module is what they share, with the standard library alone, so
a client finds the server's address without loading any robot. Every problem is a
``ConfigError`` that names the file and what it accepts.

Browsers send ``Origin`` with every websocket they open and do not hold websockets to the
same-origin rule, so the page's door (``view.door_rules``) and rosbridge's
(``transports.rosbridge.policy``) both compare it with the origins they allow (the ini's
``viewer_origins``, the flags), spelled one way by ``normalize_origin``, and both read a
URL's token with ``token_ok``. A host name that resolves to 127.0.0.1 is not enough (DNS
rebinding): the loopback names are fixed.
"""

from __future__ import annotations

import configparser
import hmac
from pathlib import Path
from typing import Any
from urllib.parse import parse_qs, urlsplit

from .errors import ConfigError

INI_NAME = "cmdinterpreter.ini"
PROJECT_DIR = Path(__file__).resolve().parent.parent
"""The project's folder (its own ``cmdinterpreter.ini``, ``robots/`` and ``commands/``)."""
DEFAULT_HOST = "127.0.0.1"
DEFAULT_PORT = 31000


def number(key: str, text: str, kind: type, low: float, high: float) -> Any:
    """Parse ``text`` as ``kind`` within [low, high], or raise ConfigError naming ``key``."""
    try:
        value = kind(text)
    except ValueError:
        raise ConfigError(
            f"{key} = {text!r} is not {'a whole number' if kind is int else 'a number'}"
        ) from None
    if not low <= value <= high:
        raise ConfigError(f"{key} = {text} is outside {low:g}..{high:g}")
    return value


def find_ini(explicit: str | Path | None) -> Path | None:
    """The ini to read: ``explicit``, else ./cmdinterpreter.ini, else the project's."""
    if explicit is not None:
        path = Path(explicit)
        if not path.is_file():
            raise ConfigError(f"config file {str(path)!r} does not exist")
        return path
    for candidate in (Path.cwd() / INI_NAME, PROJECT_DIR / INI_NAME):
        if candidate.is_file():
            return candidate
    return None


def read_ini(path: Path) -> configparser.ConfigParser:
    """The parsed ini file (``#`` and ``;`` start inline comments; no interpolation).

    Raises:
        ConfigError: it cannot be read, is not UTF-8 text, or is not an ini file.
    """
    parser = configparser.ConfigParser(interpolation=None, inline_comment_prefixes=("#", ";"))
    try:
        parser.read_string(path.read_text(encoding="utf-8"), source=str(path))
    except UnicodeDecodeError as exc:
        raise ConfigError(
            f"cannot read {path}: byte 0x{exc.object[exc.start]:02x} at offset {exc.start} "
            "is not UTF-8 text"
        ) from None
    except OSError as exc:
        raise ConfigError(f"cannot read {path}: {exc.strerror or exc}") from None
    except configparser.Error as exc:
        raise ConfigError(f"cannot read {path}: {exc}".replace("\n", " ")) from None
    return parser


def address(ini: Path | None) -> tuple[str, int]:
    """``[options] host`` and ``port`` of ``ini`` (the defaults where it says nothing).

    Raises:
        ConfigError: the file cannot be read or the port is not a port.
    """
    if ini is None:
        return DEFAULT_HOST, DEFAULT_PORT
    parser = read_ini(ini)
    host = parser.get("options", "host", fallback=DEFAULT_HOST)
    port = parser.get("options", "port", fallback=None)
    return host, DEFAULT_PORT if port is None else number("[options] port", port, int, 0, 65535)


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
