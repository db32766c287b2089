"""What the CRCL door's tests share: a live server with both doors, CRCL documents written
as NIST's samples are, and a blocking client that checks every status it reads.

``CrclServerThread`` is ``support.ServerThread`` (the text port, a recording scene)
with a ``CrclServer`` on the same loop and world. ``CrclClient`` is a plain socket,
as NIST's Java tools use one: it cuts the stream at each ``</CRCLStatus>``, parses
every status with the codec, validates it against NIST's CRCLStatus.xsd when the
schemas are at hand (``CRCL_SCHEMAS`` or ``../shared/crcl``), and checks the rules
every status keeps (StatusID increasing, an error says why).
"""

from __future__ import annotations

import os
import socket
from dataclasses import dataclass, field
from functools import cache
from pathlib import Path

from lxml import etree
from support import ROOT, ServerThread

from c2rviz.transports.crcl import CrclStatus, parse_status
from c2rviz.transports.crcl.server import CrclLimits, CrclServer

XSI = "http://www.w3.org/2001/XMLSchema-instance"
STATES = ("CRCL_Done", "CRCL_Error", "CRCL_Working", "CRCL_Ready")
DONE, ERROR, WORKING, READY = STATES[0], STATES[1], STATES[2], STATES[3]
FINAL = (DONE, ERROR)


@cache
def schema(name: str) -> etree.XMLSchema | None:
    """NIST's schema ``name`` (e.g. ``CRCLStatus.xsd``), if the schemas are at hand."""
    places = [os.environ.get("CRCL_SCHEMAS", ""), ROOT.parent / "shared" / "crcl"]
    places.append(ROOT.parent.parent / "shared" / "crcl")
    for place in places:
        path = Path(place) / name
        if place and path.is_file():
            return etree.XMLSchema(etree.parse(str(path)))
    return None


def instance(kind: str, body: str, prefix: str = "xsi", declaration: bool = True) -> bytes:
    """A command document as NIST writes them: declaration, indentation, ``xsi:type``;
    checked against CRCLCommandInstance.xsd when the schemas are at hand."""
    head = '<?xml version="1.0" encoding="UTF-8"?>\n' if declaration else ""
    doc = (
        f'{head}<CRCLCommandInstance\n  xmlns:{prefix}="{XSI}">\n'
        f'  <CRCLCommand {prefix}:type="{kind}">\n{body}\n  </CRCLCommand>\n'
        "</CRCLCommandInstance>\n"
    ).encode()
    return doc


def valid_command(doc: bytes) -> bool:
    """True when NIST's schema takes ``doc`` (or the schemas are not at hand)."""
    checker = schema("CRCLCommandInstance.xsd")
    return checker is None or checker.validate(etree.fromstring(doc))


def command(kind: str, command_id: int, body: str = "") -> bytes:
    """A command of ``kind`` (``MoveTo``: ``MoveToType``) with its CommandID and ``body``."""
    return instance(f"{kind}Type", f"    <CommandID>{command_id}</CommandID>\n{body}")


def pose(
    tag: str,
    point: tuple[float, float, float],
    x_axis: tuple[float, float, float] = (1, 0, 0),
    z_axis: tuple[float, float, float] = (0, 0, -1),
) -> str:
    """A ``PoseType`` element as NIST indents it."""
    (x, y, z), (xi, xj, xk), (zi, zj, zk) = point, x_axis, z_axis
    return f"""    <{tag}>
      <Point>
        <X>{x!r}</X> <Y>{y!r}</Y> <Z>{z!r}</Z>
      </Point>
      <XAxis>
        <I>{xi}</I> <J>{xj}</J> <K>{xk}</K>
      </XAxis>
      <ZAxis>
        <I>{zi}</I> <J>{zj}</J> <K>{zk}</K>
      </ZAxis>
    </{tag}>"""


def move_to(
    command_id: int, point: tuple[float, float, float], straight: bool = False, **axes
) -> bytes:
    """A MoveTo to ``point`` (tool x and z axes as given; z down by default)."""
    body = f"    <MoveStraight>{'true' if straight else 'false'}</MoveStraight>\n"
    return command("MoveTo", command_id, body + pose("EndPosition", point, **axes))


def actuate(command_id: int, joints: dict[int, float], speed: float | None = None) -> bytes:
    """An ActuateJoints setting joint number -> position (with a JointSpeed if given)."""
    parts = []
    for number, position in joints.items():
        details = f"<JointSpeed>{speed!r}</JointSpeed>" if speed is not None else ""
        parts.append(
            f"    <ActuateJoint>\n      <JointNumber>{number}</JointNumber>\n"
            f"      <JointPosition>{position!r}</JointPosition>\n"
            f'      <JointDetails xsi:type="JointSpeedAccelType">{details}</JointDetails>\n'
            "    </ActuateJoint>"
        )
    return command("ActuateJoints", command_id, "\n".join(parts))


@dataclass
class CrclServerThread(ServerThread):
    """``ServerThread`` (the text port) with a CRCL server on the same world."""

    crcl_limits: CrclLimits = field(default_factory=CrclLimits)
    crcl_port: int = 0

    def start(self) -> CrclServerThread:
        super().start()
        self.crcl = CrclServer(self.services, limits=self.crcl_limits)
        _, self.crcl_port = self.call_async(self.crcl.start("127.0.0.1", 0))
        return self

    def stop(self) -> None:
        if self.loop.is_running():
            self.call_async(self.crcl.stop())
        super().stop()

    def opening(self) -> float:
        return self.call(lambda: self.world.state().opening)


class CrclClient:
    """A CRCL client on a plain socket; every status read is checked (module docstring)."""

    def __init__(self, host: str, port: int, timeout: float = 60.0) -> None:
        self.sock = socket.create_connection((host, port), timeout=timeout)
        self.buffer = b""
        self.seen: list[CrclStatus] = []
        self.raw: list[bytes] = []

    def send(self, data: bytes) -> None:
        self.sock.sendall(data)

    def status(self) -> CrclStatus:
        """The next status (blocking); raises EOFError when the server closed."""
        end = b"</CRCLStatus>"
        while end not in self.buffer:
            chunk = self.sock.recv(65536)
            if not chunk:
                raise EOFError("the server closed the connection")
            self.buffer += chunk
        cut = self.buffer.index(end) + len(end)
        doc, self.buffer = self.buffer[:cut], self.buffer[cut:]
        return self._check(doc)

    def _check(self, doc: bytes) -> CrclStatus:
        checker = schema("CRCLStatus.xsd")
        if checker is not None:
            assert checker.validate(etree.fromstring(doc)), (checker.error_log, doc)
        status = parse_status(doc)
        command = status.command_status
        assert command.state in STATES
        if self.seen:
            assert command.status_id > self.seen[-1].command_status.status_id
        if command.state == ERROR:
            assert command.description, doc
        self.seen.append(status)
        self.raw.append(doc)
        return status

    def until(self, command_id: int, states: tuple[str, ...] = FINAL) -> CrclStatus:
        """Read statuses until one about ``command_id`` in one of ``states``."""
        while True:
            status = self.status()
            command = status.command_status
            if command.command_id == command_id and command.state in states:
                return status

    def ask(self, command_id: int) -> CrclStatus:
        """GetStatus: the status it answers (the pushes read before it are kept in ``seen``)."""
        before = len(self.seen)
        self.send(command("GetStatus", command_id))
        while True:
            status = self.status()
            if status.settings_status is not None and len(self.seen) > before:
                return status  # only a full status carries settings

    def run(self, doc: bytes, command_id: int) -> CrclStatus:
        """Send ``doc``; return the final status of ``command_id``."""
        self.send(doc)
        return self.until(command_id)

    def states(self, command_id: int) -> list[str]:
        """Every state seen of ``command_id``, in order."""
        return [
            s.command_status.state for s in self.seen if s.command_status.command_id == command_id
        ]

    def closed_by_server(self) -> bool:
        """True once the server has closed (reads to EOF, dropping statuses)."""
        try:
            while self.sock.recv(65536):
                pass
        except (ConnectionResetError, TimeoutError):
            return False
        return True

    def close(self) -> None:
        self.sock.close()
