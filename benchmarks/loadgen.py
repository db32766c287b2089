"""Load generators: the TCP clients and the viewer's websocket client.

Every function here is a client of a server running in another process. They
are built to cost the client as little as possible (pre-built payloads, plain
blocking sockets, one ``epoll`` loop for many connections, ``gc`` off while
timing), and the same functions measure c2rviz and the ceiling, so a ratio
between the two is a ratio between servers, not between clients.
"""

from __future__ import annotations

import asyncio
import gc
import itertools
import math
import re
import select
import socket
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Any

__all__ = [
    "ViewerClient",
    "concurrent",
    "flood",
    "joints_lines",
    "move_lines",
    "pipelined",
    "request_reply",
]

# Joint values [rad] inside the limits of every bundled robot (|q| <= 0.5).
_VALUES = [round(0.5 * math.sin(0.37 * k), 4) for k in range(97)]


def joints_lines(n_joints: int, count: int) -> list[bytes]:
    """``count`` distinct-looking ``joints`` lines for a chain of ``n_joints``."""
    cycle = itertools.cycle(_VALUES)
    return [
        b"joints " + ",".join(str(next(cycle)) for _ in range(n_joints)).encode() + b"\n"
        for _ in range(count)
    ]


def move_lines(count: int) -> list[bytes]:
    """``count`` ``move 0 v`` lines, each value different from the one before."""
    return [f"move 0 {_VALUES[k % len(_VALUES)]}\n".encode() for k in range(count)]


@contextmanager
def _no_gc() -> Iterator[None]:
    was_enabled = gc.isenabled()
    gc.collect()
    gc.disable()
    try:
        yield
    finally:
        if was_enabled:
            gc.enable()


def _connect(address: tuple[str, int]) -> socket.socket:
    sock = socket.create_connection(address, timeout=30)
    sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
    return sock


def _check_ok(received: int, lines: int) -> None:
    """Every reply of these benchmarks is ``ok\\n``: anything else is a broken run."""
    if received != 3 * lines:
        raise RuntimeError(f"expected {lines} 'ok' replies ({3 * lines} bytes), got {received}")


def pipelined(address: tuple[str, int], lines: list[bytes], repeat: int) -> float:
    """Send ``lines`` * ``repeat`` at once (one thread) while reading the replies (another).

    Returns:
        Commands answered per second, from the first byte sent to the last reply read.
    """
    payload = b"".join(lines)
    total = len(lines) * repeat
    sock = _connect(address)
    try:

        def send() -> None:
            for _ in range(repeat):
                sock.sendall(payload)

        sender = threading.Thread(target=send, daemon=True)
        with _no_gc():
            received = 0
            newlines = 0
            start = time.perf_counter()
            sender.start()
            while newlines < total:
                chunk = sock.recv(1 << 20)
                if not chunk:
                    raise RuntimeError(f"server closed after {newlines} of {total} replies")
                received += len(chunk)
                newlines += chunk.count(b"\n")
            elapsed = time.perf_counter() - start
        sender.join(timeout=30)
        _check_ok(received, total)
        return total / elapsed
    finally:
        sock.close()


def request_reply(address: tuple[str, int], lines: list[bytes], count: int) -> list[float]:
    """One client, one command at a time: send a line, wait for its reply.

    Returns:
        Every round trip [s] (after ``count // 10`` unrecorded warm-up ones).
    """
    sock = _connect(address)
    recv = sock.recv
    send = sock.sendall
    clock = time.perf_counter
    warmup = count // 10
    cycle = itertools.cycle(lines)
    times: list[float] = []
    try:
        with _no_gc():
            for k in range(warmup + count):
                line = next(cycle)
                start = clock()
                send(line)
                reply = recv(64)
                while not reply.endswith(b"\n"):
                    reply += recv(64)
                if k >= warmup:
                    times.append(clock() - start)
                if reply != b"ok\n":
                    raise RuntimeError(f"unexpected reply {reply!r}")
    finally:
        sock.close()
    return times


def concurrent(
    address: tuple[str, int], lines: list[bytes], clients: int, per_client: int
) -> tuple[float, list[float]]:
    """``clients`` connections, each sending one command at a time, driven by one epoll loop.

    Returns:
        Aggregate commands per second, and every round trip [s].
    """
    socks = [_connect(address) for _ in range(clients)]
    poller = select.epoll()
    by_fd: dict[int, socket.socket] = {}
    left: dict[int, int] = {}
    sent_at: dict[int, float] = {}
    times: list[float] = []
    clock = time.perf_counter
    n_lines = len(lines)
    try:
        for sock in socks:
            sock.setblocking(False)
            by_fd[sock.fileno()] = sock
            left[sock.fileno()] = per_client
            poller.register(sock.fileno(), select.EPOLLIN)
        with _no_gc():
            start = clock()
            for k, (fd, sock) in enumerate(by_fd.items()):
                sent_at[fd] = clock()
                sock.send(lines[k % n_lines])
            active = clients
            k = 0
            deadline = start + 120.0
            while active:
                events = poller.poll(5.0)
                if not events and clock() > deadline:
                    raise RuntimeError("concurrent clients timed out")
                for fd, _event in events:
                    sock = by_fd[fd]
                    reply = sock.recv(64)
                    if reply != b"ok\n":  # replies are 3 bytes: a split one is a broken run
                        raise RuntimeError(f"unexpected reply {reply!r}")
                    now = clock()
                    times.append(now - sent_at[fd])
                    left[fd] -= 1
                    if left[fd]:
                        k += 1
                        sent_at[fd] = clock()
                        sock.send(lines[k % n_lines])
                    else:
                        active -= 1
            elapsed = clock() - start
    finally:
        poller.close()
        for sock in socks:
            sock.close()
    return clients * per_client / elapsed, times


@dataclass
class FloodResult:
    commands: int = 0
    start: float = 0.0
    end: float = 0.0

    @property
    def rate(self) -> float:
        return self.commands / (self.end - self.start)


def flood(address: tuple[str, int], lines: list[bytes], seconds: float) -> FloodResult:
    """Send ``lines`` over and over for ``seconds`` while reading replies.

    Returns:
        The replies read within the window and the window (``time.perf_counter``).
    """
    payload = b"".join(lines)
    sock = _connect(address)
    result = FloodResult()
    stop = threading.Event()
    sent_lines = [0]

    def send() -> None:
        while not stop.is_set():
            sock.sendall(payload)
            sent_lines[0] += len(lines)

    sender = threading.Thread(target=send, daemon=True)
    try:
        received = 0
        result.start = time.perf_counter()
        result.end = result.start + seconds
        sender.start()
        counted = 0
        while True:
            chunk = sock.recv(1 << 20)
            if not chunk:
                raise RuntimeError("server closed during the flood")
            now = time.perf_counter()
            received += chunk.count(b"\n")
            if now <= result.end:
                counted = received
            elif not stop.is_set():
                stop.set()
                sender.join(timeout=30)
            if stop.is_set() and not sender.is_alive() and received >= sent_lines[0]:
                break
        result.commands = counted
    finally:
        stop.set()
        sock.close()
    return result


# The viewer side: a websocket client that speaks viser's protocol.

_POSE_TYPES = {"SetOrientationMessage", "SetPositionMessage", "SetBonePositionMessage"}
_POSE_KEYS = {"wxyz", "position", "batched_wxyzs", "batched_positions"}


def carries_pose(message: dict[str, Any]) -> bool:
    """True for a viser message that moves a scene node."""
    kind = message.get("type")
    if kind in _POSE_TYPES:
        return True
    if kind == "SceneNodeUpdateMessage":
        return bool(_POSE_KEYS & set(message.get("updates", {})))
    return False


@dataclass
class Frame:
    """One websocket frame from viser, decoded."""

    at: float
    """Arrival time (``time.perf_counter``)."""
    types: list[str]
    poses: int
    """How many of its messages move a scene node."""


def ws_url(http_url: str) -> str:
    """The websocket address of a page served at ``http_url``."""
    return re.sub(r"^http", "ws", http_url.rstrip("/"))


@dataclass
class ViewerClient:
    """A browser stand-in: connects to viser's websocket and decodes every frame.

    Viser's wire format (viser/infra/_infra.py, ``_message_producer``): the
    subprotocol is ``viser-v<version>``; each binary frame is an 8-byte
    decompressed size, an 8-byte compressed size, a zstd-compressed msgpack map
    ``{"messages": [...], "timestampSec", "binaryBufferLengths"}``, then raw buffers.
    """

    url: str
    frames: list[Frame] = field(default_factory=list)
    replay_done: asyncio.Event = field(default_factory=asyncio.Event)
    on_frame: Callable[[Frame], None] | None = None
    on_messages: Callable[[float, list[dict[str, Any]]], None] | None = None
    """Called with each frame's arrival time and its decoded messages (round 2 reads poses)."""

    async def run(self, ready: asyncio.Event | None = None) -> None:
        """Receive until cancelled or the server goes away."""
        import msgspec
        import viser
        import websockets
        import zstandard

        decompress = zstandard.ZstdDecompressor().decompress
        decode = msgspec.msgpack.decode
        async with websockets.connect(
            self.url,
            subprotocols=[websockets.Subprotocol(f"viser-v{viser.__version__}")],
            max_size=None,
            compression=None,
            ping_interval=None,
            open_timeout=10,
        ) as ws:
            if ready is not None:
                ready.set()
            async for raw in ws:
                at = time.perf_counter()
                assert isinstance(raw, bytes)
                size = int.from_bytes(raw[:8], "little")
                packed = int.from_bytes(raw[8:16], "little")
                body = decode(decompress(raw[16 : 16 + packed], max_output_size=size))
                messages = body["messages"]
                frame = Frame(
                    at,
                    [m.get("type", "?") for m in messages],
                    sum(map(carries_pose, messages)),
                )
                self.frames.append(frame)
                if "ReplayDoneMessage" in frame.types:
                    self.replay_done.set()
                if self.on_frame is not None:
                    self.on_frame(frame)
                if self.on_messages is not None:
                    self.on_messages(at, messages)

    def pose_frames_between(self, start: float, end: float) -> int:
        return sum(1 for f in self.frames if f.poses and start <= f.at <= end)
