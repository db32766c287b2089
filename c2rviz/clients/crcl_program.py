"""``c2rviz-play program.xml``: run a CRCL program over the CRCL port.

The whole ``<CRCLProgram>`` (InitCanon, MiddleCommand..., EndCanon) is read and
checked with the CRCL codec before anything is sent: a bad file is reported and
nothing moves. Then each command is sent in a ``CRCLCommandInstance`` that names the
program (``ProgramFile``, ``ProgramIndex`` from 0 for InitCanon, ``ProgramLength``),
and the next one waits for its ``CRCL_Done``. The first ``CRCL_Error`` stops the run
and is shown with its ``StateDescription`` and the command's index.

Exit status: 0 every command done; 1 a command got CRCL_Error, or the server could
not be reached or went away; 2 the file or the options are wrong (nothing was sent);
130 interrupted.

It uses the CRCL codec's pure modules only (``transports.crcl``: no server side).
"""

from __future__ import annotations

import argparse
import socket
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from typing import TextIO

from ..errors import C2rvizError
from ..ini import find_ini, number, read_ini
from ..transports.crcl.commands import Command
from ..transports.crcl.documents import CommandInstance, parse_program, write_instance
from ..transports.crcl.errors import CrclError
from ..transports.crcl.framing import DocumentSplitter
from ..transports.crcl.status import CrclStatus, parse_status
from .connection import ServerUnavailable, default_address, dial, find_script

CRCL_PORT = 64444
"""The CRCL port when neither ``--port`` nor the ini's ``crcl_port`` says."""


def is_crcl_program(name: str) -> bool:
    """True for a file ``c2rviz-play`` runs as a CRCL program (its name ends in ``.xml``)."""
    return name.lower().endswith(".xml")


def crcl_address(
    host: str | None, port: int | None, config: str | Path | None = None
) -> tuple[str, int]:
    """Where the CRCL door is: the flags, else the ini (``host``, ``crcl_port``), else
    127.0.0.1:64444.

    Raises:
        ConfigError: ``config`` does not exist, or the ini has a bad value.
    """
    if host is not None and port is not None:
        return host, port
    ini_host, _ = default_address(config)
    ini = find_ini(config)
    ini_port = CRCL_PORT
    if ini is not None:
        text = read_ini(ini).get("options", "crcl_port", fallback=None)
        if text is not None:
            ini_port = number("[options] crcl_port", text, int, 0, 65535)
    return host or ini_host, ini_port if port is None else port


class _Statuses:
    """The statuses a socket brings, one at a time (split at each document's end)."""

    def __init__(self, sock: socket.socket) -> None:
        self.sock = sock
        self.splitter = DocumentSplitter(roots=("CRCLStatus",))
        self.ready: list[bytes] = []

    def next(self) -> CrclStatus:
        while not self.ready:
            data = self.sock.recv(65536)
            if not data:
                raise ConnectionError("the server closed the connection")
            for item in self.splitter.feed(data):
                if isinstance(item, CrclError):
                    raise item
                self.ready.append(item)
        return parse_status(self.ready.pop(0))


def run(
    sock: socket.socket,
    commands: Sequence[Command],
    name: str,
    out: TextIO,
    err: TextIO,
    *,
    quiet: bool = False,
) -> int:
    """Send every command and wait for each one's CRCL_Done; return the index of the
    command that got CRCL_Error, or -1 when all were done (``quiet``: show the error
    alone, not each command)."""
    statuses = _Statuses(sock)
    width = len(str(len(commands)))
    for index, command in enumerate(commands):
        what = f"{command.XSI_TYPE} (CommandID {command.command_id})"
        label = f"[{index:>{width}}/{len(commands) - 1}] {what}"
        instance = CommandInstance(
            command=command,
            program_file=name,
            program_index=index,
            program_length=len(commands),
        )
        sock.sendall(write_instance(instance))
        while True:
            state = statuses.next().command_status
            if state.state == "CRCL_Error":  # about this command: the ones before are done
                if not quiet:
                    print(f"{label}: error", file=out, flush=True)
                print(
                    f"{name}: command {index} ({command.XSI_TYPE}, CommandID "
                    f"{command.command_id}): {state.description}",
                    file=err,
                    flush=True,
                )
                return index
            if state.command_id == command.command_id and state.state == "CRCL_Done":
                if not quiet:
                    print(f"{label}: done", file=out, flush=True)
                break
    return -1


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="c2rviz-play",
        description="Run a CRCL program (a <CRCLProgram> .xml file) over c2rviz's CRCL port: "
        "each command waits for the one before to be CRCL_Done; the first CRCL_Error stops.",
        epilog="Exit status: 0 all commands done; 1 a command got CRCL_Error or no server; "
        "2 the file or an option does not check (nothing was sent).",
    )
    add = parser.add_argument
    add("file", metavar="PROGRAM.xml", help="CRCL program file")
    add("--host", help="the CRCL door (default from cmdinterpreter.ini: 127.0.0.1)")
    add("--port", type=int, help="the CRCL port (default from cmdinterpreter.ini: 64444)")
    add("--config", metavar="PATH", help="ini file for host and crcl_port")
    add(
        "--timeout",
        type=float,
        default=10.0,
        metavar="S",
        help="keep retrying the connection for S seconds, then give up (default 10)",
    )
    add("--check", action="store_true", help="only read and check the program; do not connect")
    add("--quiet", "-q", action="store_true", help="print errors and the summary line only")
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run a CRCL program file; returns the exit status (see the module docstring)."""
    args = build_parser().parse_args(argv)
    out, err = sys.stdout, sys.stderr
    try:
        path = find_script(args.file)
        commands = parse_program(path.read_bytes())
        host, port = crcl_address(args.host, args.port, args.config)
    except (OSError, C2rvizError) as exc:
        where = f"{args.file}: " if isinstance(exc, CrclError) else ""
        print(f"c2rviz-play: {where}{exc}", file=err)
        return 2
    except Exception as exc:  # the codec's slip on a hostile document: one line, never a trace
        problem = f"{type(exc).__name__}: {exc}"
        print(f"c2rviz-play: {args.file}: not a CRCL program this can read ({problem})", file=err)
        return 2
    name = path.name
    if args.check:
        print(f"{name}: {len(commands)} CRCL commands, all check", file=out)
        return 0

    def notify(message: str) -> None:
        print(f"c2rviz-play: {message}", file=err, flush=True)

    start = time.monotonic()
    try:
        sock = dial(host, port, args.timeout, notify)
    except ServerUnavailable as exc:
        notify(str(exc).replace("c2rviz server", "c2rviz CRCL door"))
        return 1
    try:
        failed = run(sock, commands, name, out, err, quiet=args.quiet)
    except (ConnectionError, OSError, CrclError) as exc:
        notify(f"connection to {host}:{port} lost: {exc}")
        return 1
    except KeyboardInterrupt:
        notify("interrupted")
        return 130
    finally:
        sock.close()
    if failed >= 0:
        return 1
    elapsed = time.monotonic() - start
    print(f"{name}: {len(commands)} CRCL commands, all done, in {elapsed:.2f} s", file=out)
    return 0
