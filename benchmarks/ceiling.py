"""The ceiling: the leanest pure-asyncio line server we can write.

It does what every command server must do and nothing more: split each chunk
into lines, parse a ``joints`` list into floats, and answer all complete lines
of the chunk with one ``write`` of ``ok`` lines. No validation, no state, no
scene. The benchmarks run it next to c2rviz, with the same clients, so every
figure has a ratio against what plain asyncio on this machine can do.

With ``--viser-port P`` it is also the floor for the viewer rows: a bare viser
server with one box per chain joint; the last ``joints``/``move`` of each chunk
turns them and flushes viser at once (no rate limit, no kinematics).

Run alone: ``python benchmarks/ceiling.py --port 0`` prints
``ceiling: commands on HOST:PORT`` (and ``ceiling: viewer at URL``) and serves
until SIGINT/SIGTERM.
"""

from __future__ import annotations

import argparse
import asyncio
import math
import signal
import sys
from collections.abc import Sequence
from typing import Any

__all__ = ["LineProtocol", "main", "serve"]


class LineProtocol(asyncio.Protocol):
    """One client: split lines, parse ``joints`` lists into floats, one write per chunk."""

    def __init__(self, view: Any = None) -> None:
        self.transport: asyncio.Transport | None = None
        self.rest = b""
        self.view = view

    def connection_made(self, transport: asyncio.BaseTransport) -> None:
        assert isinstance(transport, asyncio.Transport)
        self.transport = transport

    def data_received(self, data: bytes) -> None:
        if self.rest:
            data = self.rest + data
        lines = data.split(b"\n")
        self.rest = lines.pop()
        if not lines:
            return
        values: list[float] = []
        for line in lines:
            verb, _, args = line.partition(b" ")
            if verb == b"joints":
                values = [float(value) for value in args.split(b",")]
            elif verb == b"move":
                values = [float(value) for value in args.partition(b" ")[2].split(b",")]
        assert self.transport is not None
        self.transport.write(b"ok\n" * len(lines))
        if self.view is not None and values:
            self.view.show(values)


class View:
    """The viewer floor: one box per joint, turned and flushed on every chunk."""

    def __init__(self, host: str, port: int, boxes: int = 7) -> None:
        import viser

        self.server = viser.ViserServer(host=host, port=port, verbose=False)
        self.boxes = [
            self.server.scene.add_box(f"/box{i}", dimensions=(0.1, 0.1, 0.1), position=(0, 0, i))
            for i in range(boxes)
        ]
        self.url = f"http://{host}:{self.server.get_port()}"

    def show(self, values: list[float]) -> None:
        for box, value in zip(self.boxes, values):
            box.wxyz = (math.cos(value / 2), 0.0, 0.0, math.sin(value / 2))
        self.server.flush()

    def stop(self) -> None:
        self.server.stop()


async def serve(host: str, port: int, viser_port: int | None = None) -> int:
    """Serve until SIGINT or SIGTERM."""
    loop = asyncio.get_running_loop()
    view = View(host, viser_port) if viser_port is not None else None
    server = await loop.create_server(lambda: LineProtocol(view), host, port)
    stop = asyncio.Event()
    for sig in (signal.SIGINT, signal.SIGTERM):
        loop.add_signal_handler(sig, stop.set)
    bound_host, bound_port = server.sockets[0].getsockname()[:2]
    print(f"ceiling: commands on {bound_host}:{bound_port}", flush=True)
    if view is not None:
        print(f"ceiling: viewer at {view.url}", flush=True)
    try:
        await stop.wait()
    finally:
        server.close()
        await server.wait_closed()
        if view is not None:
            view.stop()
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--host", default="127.0.0.1")
    parser.add_argument("--port", type=int, default=0)
    parser.add_argument("--viser-port", type=int, help="also run the viewer floor on this port")
    args = parser.parse_args(argv)
    return asyncio.run(serve(args.host, args.port, args.viser_port))


if __name__ == "__main__":
    sys.exit(main())
