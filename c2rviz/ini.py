"""Reading ``cmdinterpreter.ini``: where it is, its text, and its numbers.

The server's settings (``app.config``) and the clients (``clients.options``) both
read the ini; this module is what they share, with the standard library alone, so
a client finds the server's address without loading any robot. Every problem is a
``ConfigError`` that names the file and what it accepts.
"""

from __future__ import annotations

import configparser
from pathlib import Path
from typing import Any

from .errors import ConfigError

__all__ = [
    "DEFAULT_HOST",
    "DEFAULT_PORT",
    "INI_NAME",
    "PROJECT_DIR",
    "address",
    "find_ini",
    "number",
    "read_ini",
]

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
