"""What a client takes from its flags and the ini: where the server is, where command files are
(the working directory, then the recording folder, then the project's ``commands/``).

Shared by ``c2rviz-cli`` and ``c2rviz-play`` (re-exported by ``client``). It reads
the ini with the settings reader alone: no robot is loaded.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from ..errors import C2rvizError
from ..ini import INI_NAME, PROJECT_DIR, address, find_ini, read_ini

__all__ = [
    "COMMANDS_DIR",
    "add_connection_args",
    "default_address",
    "find_script",
    "recording_folder",
    "server_address",
]

COMMANDS_DIR = PROJECT_DIR / "commands"
"""The project's bundled command files."""


def add_connection_args(parser: argparse.ArgumentParser) -> None:
    """The flags every client shares: where the server is and how long to retry."""
    add = parser.add_argument
    add("--host", help="command server (default from cmdinterpreter.ini: 127.0.0.1)")
    add("--port", type=int, help="command port (default from cmdinterpreter.ini: 31000)")
    add("--config", metavar="PATH", help="ini file for host and port")
    add(
        "--timeout",
        type=float,
        default=10.0,
        metavar="S",
        help="keep retrying the connection for S seconds, then give up (default 10)",
    )


def default_address(config: str | Path | None = None) -> tuple[str, int]:
    """Host and port from cmdinterpreter.ini (``[options] host/port``), else 127.0.0.1:31000.

    An unspecified bind address (``0.0.0.0``, ``::``) in the ini means "this machine"
    to a client, so it becomes the loopback address.

    Raises:
        ConfigError: ``config`` does not exist, or the ini has a bad value.
    """
    host, port = address(find_ini(config))
    if host in ("", "0.0.0.0"):
        host = "127.0.0.1"
    elif host == "::":
        host = "::1"
    return host, port


def server_address(
    host: str | None, port: int | None, config: str | Path | None = None
) -> tuple[str, int]:
    """Where to connect: ``--host``/``--port`` where given, the rest from the ini.

    Args:
        host: The ``--host`` flag (None: not given).
        port: The ``--port`` flag (None: not given; 0 is a port).
        config: The ``--config`` flag (None: the usual ini search).

    Raises:
        ConfigError: the ini is needed and ``config`` does not exist or has a bad value.
    """
    if host is not None and port is not None:
        return host, port
    ini_host, ini_port = default_address(config)
    return host or ini_host, ini_port if port is None else port


def recording_folder(config: str | Path | None = None) -> Path:
    """Where the server puts recordings, as a client reads the ini: the user's ini's
    ``[options] record_dir`` (relative to that ini), else ``./recordings`` of the working
    directory (the project's own ini does not count: its folder is not the user's).

    A bad or unreadable ini is no reason to fail a search: ``./recordings`` then.
    """
    here = Path.cwd() / "recordings"
    try:
        ini = find_ini(config)
        if ini is None or ini.resolve() == (PROJECT_DIR / INI_NAME).resolve():
            return here
        folder = read_ini(ini).get("options", "record_dir", fallback=None)
    except C2rvizError:
        return here
    return here if not folder else ini.parent / folder


def find_script(name: str | Path, config: str | Path | None = None) -> Path:
    """A command file: ``name`` as given (relative to the working directory), else in
    the recording folder (``recording_folder``), else in the project's ``commands/``.

    Raises:
        FileNotFoundError: in none of them (the message names each place looked in).
    """
    path = Path(name)
    if path.is_file():
        return path
    looked = [str(path if path.is_absolute() else Path.cwd() / path)]
    if not path.is_absolute():
        for folder in (recording_folder(config), COMMANDS_DIR):
            candidate = folder / path
            if candidate.is_file():
                return candidate
            looked.append(str(candidate))
    raise FileNotFoundError(f"no command file {str(name)!r}: looked for {', '.join(looked)}")
