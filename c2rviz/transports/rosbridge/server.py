"""The rosbridge v2 websocket server: frames in, ``Bridge`` calls out, answers back.

``RosbridgeServer`` serves ``ws://127.0.0.1:9090/`` (loopback by default) with
websockets' asyncio server. The opening handshake is screened by the policy
(``policy.RosbridgePolicy``): a browser from a foreign origin, or a request
without the token, gets HTTP 403. Then each connection is a loop over its
frames, handled one after another (a request that waits, a service call or a
publish, holds the connection's later requests, never another connection's):

* ``subscribe`` / ``unsubscribe``: one ``Outbox`` per topic spelling, fed by
  ``Bridge.subscribe``; ``throttle_rate`` and ``queue_length`` honoured, latest wins;
* ``advertise`` / ``unadvertise`` / ``publish``: published messages go to
  ``Bridge.publish`` (advertising first is optional, as in rosbridge);
* ``call_service``: ``/rosapi/*`` is answered here (``rosapi``), anything else
  by ``Bridge.call_service``; the ``service_response`` carries the request's id,
  with ``result: false`` and the error's text when refused;
* ``set_level``: which ``status`` frames the client gets (``error`` by default).

Every error is answered with a ``status`` naming the problem and the request's
``id``; the connection goes on. Frames over ``max_frame_bytes`` close the
connection with code 1009, one connection over ``max_connections`` is closed
with 1013. Binary frames are answered with a status: c2rviz speaks JSON text.
A connection is read at most ``max_read_ahead`` frames ahead of the one served
(then reading it stops until it catches up: the client's sends wait, as TCP
makes them). A client that does not let its connection close (it never reads) is dropped
after ``CLOSE_TIMEOUT_S``.
"""

from __future__ import annotations

import asyncio
import logging
from collections import Counter
from collections.abc import Callable
from http import HTTPStatus
from typing import Any

from websockets.asyncio.server import Server, ServerConnection, serve
from websockets.frames import CloseCode
from websockets.http11 import Request, Response

from ..parse_process import ParseProcess
from . import protocol, rosapi
from .bridge import Bridge
from .connection import Connection
from .messages import normalize_type
from .policy import RosbridgePolicy

log = logging.getLogger("c2rviz.rosbridge")

CLOSE_TIMEOUT_S = 1.0
"""Longest wait for a client to answer the closing handshake (at shutdown, or when a
connection is closed) before its connection is dropped [s]: a client that never
reads cannot hold the program's stop longer (websockets' default is 10 s)."""


class RosbridgeServer:
    """A rosbridge v2 endpoint in front of a ``Bridge``.

    Args:
        bridge: c2rviz as rosbridge sees it.
        policy: Origins, token and limits.
        node_name: The node ``/rosapi/nodes`` names.
        sent_probe: Called with the monotonic time [s] of each message's
            delivery just after its frame was written (benchmarks; None).

    Attributes:
        stats: Counts: ``sent`` frames of subscriptions, ``thinned`` messages
            (pushed out of an outbox unsent), ``errors`` answered, and refusals
            ``refused origin``, ``refused token``, ``refused connections``.
    """

    def __init__(
        self,
        bridge: Bridge,
        policy: RosbridgePolicy | None = None,
        *,
        node_name: str = "/c2rviz",
        sent_probe: Callable[[float], None] | None = None,
    ) -> None:
        self.bridge = bridge
        self.policy = policy or RosbridgePolicy()
        self.node_name = node_name
        self.sent_probe = sent_probe
        self.stats: Counter[str] = Counter()
        self._server: Server | None = None
        self._connections: set[Connection] = set()
        self._encoded: dict[str, tuple[dict[str, Any], str]] = {}
        self.decoding: ParseProcess | None = None
        """The process large frames are decoded in (``connection.DECODE_ON_LOOP_BYTES``),
        one for every client, in the order they came; while the server runs (its process
        starts with the first large frame)."""
        bridge.hang_up_with(self.hang_up)

    async def start(self, host: str = "127.0.0.1", port: int = 9090) -> tuple[str, int]:
        """Listen on ``host:port`` (0: any free port); return the address bound."""
        self.decoding = ParseProcess("rosbridge decoding")
        self._server = await serve(
            self._handle,
            host,
            port,
            process_request=self._screen,
            max_size=self.policy.max_frame_bytes,
            max_queue=self.policy.max_read_ahead,
            close_timeout=CLOSE_TIMEOUT_S,
            compression="deflate" if self.policy.compression else None,
        )
        bound = next(iter(self._server.sockets)).getsockname()
        return str(bound[0]), int(bound[1])

    async def stop(self) -> None:
        """Close every connection (code 1001) and the listening socket; idempotent.

        A request still being served (a service call that waits on a motion) is
        given up: its client gets no answer, the connection closes. A client that
        has not let its connection close within ``CLOSE_TIMEOUT_S`` (it never reads,
        so a send and the closing handshake wait on it) is dropped.
        """
        if self._server is not None:
            for connection in self._connections:
                connection.stop()
            self._server.close()
            closed = asyncio.ensure_future(self._server.wait_closed())
            await asyncio.wait((closed,), timeout=CLOSE_TIMEOUT_S)
            if not closed.done():  # a client that never reads holds a send, and the close
                for websocket in list(self._server.handlers):
                    websocket.transport.abort()
                await closed
            self._server = None
        if self.decoding is not None:
            decoding, self.decoding = self.decoding, None
            await decoding.close()

    async def __aenter__(self) -> RosbridgeServer:
        return self

    async def __aexit__(self, *exc: object) -> None:
        await self.stop()

    def hang_up(self, source: str) -> None:
        """Close the client ``source``'s connection (``Connection.hang_up``); none: nothing."""
        for connection in list(self._connections):
            if connection.source == source:
                connection.hang_up()

    @property
    def connections(self) -> int:
        """Clients connected now."""
        return len(self._connections)

    def graph(self) -> rosapi.Graph:
        """What rosapi tells of c2rviz now (types in the ROS 2 spelling)."""
        return rosapi.Graph(
            topics=tuple((name, normalize_type(kind)) for name, kind in self.bridge.topics()),
            services=tuple(
                (name, normalize_type(kind, "srv")) for name, kind in self.bridge.services()
            ),
            nodes=(self.node_name,),
            params=self.bridge.params(),
        )

    def encode(self, spelling: str, msg: dict[str, Any]) -> str | None:
        """The ``publish`` frame of ``msg`` on ``spelling``, made once for all subscribers."""
        cached = self._encoded.get(spelling)
        if cached is not None and cached[0] is msg:
            return cached[1]
        try:
            text = protocol.publish(spelling, msg)
        except (TypeError, ValueError) as error:
            self.stats["unsendable"] += 1
            log.error("rosbridge: a message on %s cannot be sent as JSON: %s", spelling, error)
            return None
        self._encoded[spelling] = (msg, text)
        return text

    def _screen(self, connection: ServerConnection, request: Request) -> Response | None:
        """Refuse a browser from a foreign origin, or a request without the token (HTTP 403)."""
        origins = request.headers.get_all("Origin")
        origin = origins[0] if len(origins) == 1 else None
        if len(origins) > 1 or not self.policy.origin_ok(origin):
            origin = ", ".join(origins)
            self.stats["refused origin"] += 1
            log.warning(
                "rosbridge: refused a websocket from origin %r: allowed are %s",
                origin,
                ", ".join(self.policy.origins()),
            )
            return connection.respond(HTTPStatus.FORBIDDEN, "origin not allowed\n")
        if not self.policy.token_ok(request.path):
            self.stats["refused token"] += 1
            log.warning("rosbridge: refused a websocket without the token")
            return connection.respond(HTTPStatus.FORBIDDEN, "token required\n")
        return None

    async def _handle(self, websocket: ServerConnection) -> None:
        limit = self.policy.max_connections
        if len(self._connections) >= limit:
            self.stats["refused connections"] += 1
            reason = f"too many rosbridge connections (limit {limit})"
            await websocket.close(CloseCode.TRY_AGAIN_LATER, reason)
            return
        connection = Connection(self, websocket)
        self._connections.add(connection)
        self.bridge.opened(connection.source)
        try:
            await connection.run()
            if connection.stopping:  # as websockets closes the others when the server stops
                await websocket.close(CloseCode.GOING_AWAY)
        finally:
            self._connections.discard(connection)
            await connection.close()
            self.bridge.closed(connection.source)
