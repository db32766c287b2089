"""One rosbridge client: its frames served in order, its subscriptions and advertisements.

Each frame is read by ``protocol.parse_frame`` and served by one method; a
request that waits (a publish taken by the session, a service call) holds the
connection's later requests, never another connection's. Every error becomes a
``status`` naming it, with the request's ``id``, and also where a roslibpy user
reads it (roslibpy drops ``status`` frames): for ``call_service`` a
``service_response`` with ``result: false``, otherwise ``error: ...`` on the
client's own subscription to ``[NS]/c2rviz/reply``; the connection goes on.
"""

from __future__ import annotations

import asyncio
import dataclasses
import logging
from collections import Counter
from collections.abc import Callable, Collection, Mapping
from typing import Any, Protocol

from websockets.asyncio.server import ServerConnection
from websockets.exceptions import ConnectionClosed
from websockets.frames import CloseCode

from ...errors import C2rvizError
from ..parse_process import ParseProcess
from . import messages, protocol, rosapi
from .bridge import Bridge
from .inputs import CommandRefused
from .ops import FrameId, op_name, resolve_name
from .outbox import Outbox
from .policy import RosbridgePolicy
from .protocol import LEVELS, SUPPORTED_OPS, RosbridgeError

log = logging.getLogger("c2rviz.rosbridge")

DECODE_ON_LOOP_BYTES = 16384
"""The largest frame decoded on the event loop [bytes]; a larger one (a trajectory of
thousands of points) is decoded and its message read in the server's decoding process
(``parse_process``), the other clients served meanwhile, this client's next frames
after it; a trajectory naming a joint its robot lacks comes back as its outline
(``messages.TrajectoryOutline``), refused without its points taken in."""
REPLY_TOPIC = "/c2rviz/reply"
"""The reply topic's name under each robot's namespace (``[NS]/c2rviz/reply``)."""


class Host(Protocol):
    """What a connection needs of its server (``server.RosbridgeServer``)."""

    bridge: Bridge
    policy: RosbridgePolicy
    stats: Counter[str]
    sent_probe: Callable[[float], None] | None
    decoding: ParseProcess | None

    def graph(self) -> rosapi.Graph: ...

    def encode(self, spelling: str, msg: dict[str, Any]) -> str | None: ...


def _decode(
    text: str, topics: dict[str, str], joints: Mapping[str, Collection[str]]
) -> tuple[protocol.Op, object]:
    """In the decoding process: the frame's request and, for a publish to a topic whose
    message c2rviz reads (a trajectory, a joint state), that reading
    (``messages.read_ahead``; a trajectory naming a joint not in ``joints`` of its topic,
    only its outline). The message itself then stays here: its reader is what takes it
    (``Bridge.publish``), and it would cost the loop as much to take in again."""
    op = protocol.parse_frame(text)
    if isinstance(op, protocol.Publish):
        name = resolve_name(op.topic)
        kind = topics.get(name)
        reading = None if kind is None else messages.read_ahead(kind, op.msg, joints.get(name))
        if reading is not None:
            return dataclasses.replace(op, msg={}), reading
    return op, None


class Connection:
    """One client: its status level, subscriptions and advertised topics."""

    def __init__(self, server: Host, websocket: ServerConnection) -> None:
        self.server, self.websocket = server, websocket
        self.bridge, self.policy = server.bridge, server.policy
        host, port = websocket.remote_address[:2]
        self.source = f"rosbridge {host}:{port}"
        self.level = "error"
        self.outboxes: dict[str, Outbox] = {}
        self.advertised: dict[str, str] = {}
        self.stopping = False
        self._serving: asyncio.Future[None] | None = None
        self._hanging_up: asyncio.Future[None] | None = None

    async def run(self) -> None:
        """Serve the connection's frames in order until it closes or the server stops.

        A client that leaves while its request waits (a service call on a long
        move) gives that request up at once: nobody is left to answer.
        """
        gone = asyncio.ensure_future(self.websocket.wait_closed())
        try:
            async for frame in self.websocket:
                if self.stopping:
                    break
                serving = self._serving = asyncio.ensure_future(self.handle(frame))
                try:
                    await asyncio.wait((serving, gone), return_when=asyncio.FIRST_COMPLETED)
                    if not serving.done():  # the client left while its request waited
                        serving.cancel()
                        await asyncio.gather(serving, return_exceptions=True)
                        break
                    serving.result()
                except asyncio.CancelledError:
                    if self.stopping or serving.cancelled():
                        break
                    serving.cancel()  # this task is cancelled: its request goes with it
                    raise
                finally:
                    self._serving = None
        except ConnectionClosed:
            pass
        finally:
            gone.cancel()

    def stop(self) -> None:
        """Give up the request being served (a service call that waits) and read no more."""
        self.stopping = True
        if self._serving is not None:
            self._serving.cancel()

    def hang_up(self) -> None:
        """Cut this client off (``fault disconnect``): read no more, and close with code 1012
        (service restart: it may connect again) on the loop's next turn. By then the answer
        to the request that cut it off is out; a request still waiting (a service call on a
        move, a reply a latency delays) is given up, as the text port gives it up."""
        if not self.stopping:
            self.stopping = True
            asyncio.get_running_loop().call_soon(self._hung_up)

    def _hung_up(self) -> None:
        if self._serving is not None and not self._serving.done():
            self._serving.cancel()
        close = self.websocket.close(CloseCode.SERVICE_RESTART, "fault disconnect")
        self._hanging_up = asyncio.ensure_future(close)

    async def handle(self, frame: str | bytes) -> None:
        """Serve one frame; any error becomes a status (and a failed service_response)."""
        if isinstance(frame, bytes):
            problem = "binary frames (CBOR, BSON) are not read: send JSON text frames"
            await self.refuse(RosbridgeError(problem))
        else:
            await self.handle_text(frame)

    async def close(self) -> None:
        """Stop every subscription of the connection (at its end)."""
        outboxes, self.outboxes = list(self.outboxes.values()), {}
        for outbox in outboxes:
            try:
                self.bridge.unsubscribe(outbox.handle)
            except Exception:
                log.exception("rosbridge: unsubscribing %s failed", outbox.spelling)
            await outbox.close()

    async def handle_text(self, text: str) -> None:
        op: protocol.Op | None = None
        reading: object = None
        try:
            decoding = self.server.decoding
            if len(text) > DECODE_ON_LOOP_BYTES and decoding is not None:
                topics = dict(self.server.graph().topics)
                joints = self.bridge.trajectory_joints()
                decoded, reading = await decoding.run(_decode, text, topics, joints)
            else:
                decoded = protocol.parse_frame(text)
            op = decoded
            if reading is not None and isinstance(decoded, protocol.Publish):
                messages.remember(decoded.msg, reading)
            await self.serve(decoded)
        except (asyncio.CancelledError, ConnectionClosed):
            raise
        except RosbridgeError as error:
            await self.refuse(error, op)
        except C2rvizError as error:
            await self.refuse(error, op)
        except Exception:
            log.exception("rosbridge: %s failed on %s", self.source, text[:200])
            await self.refuse(C2rvizError("internal error in c2rviz (see its log)"), op)
        finally:
            if reading is not None and isinstance(op, protocol.Publish):
                messages.forget(op.msg)

    async def serve(self, op: protocol.Op) -> None:
        if isinstance(op, protocol.Subscribe):
            await self.subscribe(op)
        elif isinstance(op, protocol.Unsubscribe):
            await self.unsubscribe(op)
        elif isinstance(op, protocol.Advertise):
            await self.advertise(op)
        elif isinstance(op, protocol.Unadvertise):
            if self.advertised.pop(op.topic, None) is None:
                await self.status("warning", f"unadvertise: {op.topic} is not advertised", op.id)
        elif isinstance(op, protocol.Publish):
            await self.bridge.publish(self.source, resolve_name(op.topic), op.msg)
        elif isinstance(op, protocol.CallService):
            await self.call_service(op)
        elif isinstance(op, protocol.SetLevel):
            self.level = op.level
        else:
            served = ", ".join(SUPPORTED_OPS)
            problem = f"is not served by c2rviz (it serves: {served})"
            raise RosbridgeError(problem, op.id, op.op)

    def topic_type(self, op: str, topic: str, id: FrameId) -> str:
        """The type of ``topic`` (as spelled), or an error naming the topics there are."""
        topics = dict(self.server.graph().topics)
        kind = topics.get(resolve_name(topic))
        if kind is None:
            raise RosbridgeError(f"no topic {topic} (topics: {', '.join(sorted(topics))})", id, op)
        return kind

    def room(self, op: str, id: FrameId, used: int, what: str) -> None:
        """Refuse one more subscription or advertisement past the connection's limit."""
        limit = self.policy.max_subscriptions
        if used >= limit:
            problem = f"too many {what} on this connection (limit {limit}); un{op} some first"
            raise RosbridgeError(problem, id, op)

    async def subscribe(self, op: protocol.Subscribe) -> None:
        if op.compression != "none":
            problem = f"compression {op.compression!r} is not served: c2rviz sends JSON ('none')"
            raise RosbridgeError(problem, op.id, "subscribe")
        kind = self.topic_type("subscribe", op.topic, op.id)
        if op.type is not None and op.type != kind:
            raise RosbridgeError(f"{op.topic} has type {kind}, not {op.type}", op.id, "subscribe")
        outbox = self.outboxes.get(op.topic)
        if outbox is None or op.id not in outbox.requests:
            used = sum(len(o.requests) for o in self.outboxes.values())
            self.room("subscribe", op.id, used, "subscriptions")
        length = min(op.queue_length, self.policy.max_queue_length)
        if length < op.queue_length:
            text = f"subscribe: queue_length {op.queue_length} cut to {length}"
            await self.status("warning", text, op.id)
        if outbox is not None:
            outbox.request(op.id, op.throttle_rate_ms, length)
            return
        server = self.server
        name = resolve_name(op.topic)
        outbox = Outbox(
            op.topic,
            self.websocket.send,
            server.encode,
            server.stats,
            server.sent_probe,
            snapshot=lambda: self.bridge.snapshot(name),
            unthrottled_length=self.policy.max_queue_length,
        )
        outbox.request(op.id, op.throttle_rate_ms, length)
        outbox.handle = self.bridge.subscribe(name, outbox.deliver)
        self.outboxes[op.topic] = outbox
        outbox.start()

    async def unsubscribe(self, op: protocol.Unsubscribe) -> None:
        outbox = self.outboxes.get(op.topic)
        if outbox is None or (op.id is not None and op.id not in outbox.requests):
            which = "" if op.id is None else f" with id {op.id!r}"
            await self.status(
                "warning", f"unsubscribe: no subscription to {op.topic}{which}", op.id
            )
            return
        outbox.drop(op.id)
        if not outbox.requests:
            del self.outboxes[op.topic]
            self.bridge.unsubscribe(outbox.handle)
            await outbox.close()

    async def advertise(self, op: protocol.Advertise) -> None:
        kind = self.topic_type("advertise", op.topic, op.id)
        if op.type != kind:
            raise RosbridgeError(f"{op.topic} has type {kind}, not {op.type}", op.id, "advertise")
        if op.topic not in self.advertised:
            self.room("advertise", op.id, len(self.advertised), "advertised topics")
        self.advertised[op.topic] = kind

    async def call_service(self, op: protocol.CallService) -> None:
        name = resolve_name(op.service)
        graph = self.server.graph()
        try:
            if rosapi.is_rosapi(name):
                values = rosapi.answer(name, op.args, graph)
            elif name in dict(graph.services):
                values = await self.bridge.call_service(self.source, name, op.args)
            else:
                known = sorted([s for s, _ in graph.services] + list(rosapi.ROSAPI_SERVICES))
                problem = f"no service {op.service} (services: {', '.join(known)})"
                raise RosbridgeError(problem, op.id, "call_service")
        except (asyncio.CancelledError, ConnectionClosed):
            raise
        except Exception as error:
            if not isinstance(error, C2rvizError):
                log.exception("rosbridge: %s failed on call_service %s", self.source, name)
                error = C2rvizError("internal error in c2rviz (see its log)")
            text = (
                str(error)
                if isinstance(error, RosbridgeError)
                else f"call_service {op.service}: {error}"
            )
            self.server.stats["errors"] += 1
            await self.send(protocol.service_response(op.id, op.service, text, False))
            await self.status("error", text, op.id)
            return
        await self.send(protocol.service_response(op.id, op.service, values, True))

    async def refuse(self, error: C2rvizError, op: protocol.Op | None = None) -> None:
        """Answer a refused request: a status error, and where a roslibpy user reads it
        (roslibpy has no handler for ``status``): a failed service_response for a
        service call, else an ``error: ...`` line on the reply topic this client
        subscribes to (``[NS]/c2rviz/reply``), as the text port would answer."""
        self.server.stats["errors"] += 1
        if isinstance(error, RosbridgeError):
            id, text = error.id, str(error)
            if error.op == "call_service" and error.service is not None:
                await self.send(protocol.service_response(id, error.service, text, False))
            elif error.op != "call_service":
                self.reply_error(text, getattr(op, "topic", None))
        else:
            id = op.id if op is not None else None
            what = op_name(op) if op is not None else "request"
            target = getattr(op, "topic", None) or getattr(op, "service", None)
            text = f"{what} {target}: {error}" if target else f"{what}: {error}"
            if not isinstance(error, CommandRefused):  # its reply is on the topic already
                self.reply_error(text, getattr(op, "topic", None))
        await self.status("error", text, id)

    def reply_error(self, text: str, topic: str | None) -> None:
        """Put ``error: text`` on this client's reply subscription for ``topic``'s robot
        (its namespace; every reply subscription when the frame named no topic)."""
        replies = {
            name.removesuffix(REPLY_TOPIC): outbox
            for name, outbox in ((resolve_name(t), o) for t, o in self.outboxes.items())
            if name == REPLY_TOPIC or name.endswith(REPLY_TOPIC)
        }
        if topic is not None:
            where = resolve_name(topic)
            matching = [ns for ns in replies if where.startswith(ns + "/")]
            chosen = [max(matching, key=len)] if matching else []
        else:
            chosen = list(replies)
        for namespace in chosen:
            replies[namespace].deliver({"data": f"error: {text}"})

    async def status(self, level: str, text: str, id: FrameId) -> None:
        if LEVELS.index(level) <= LEVELS.index(self.level):
            await self.send(protocol.status(level, text, id))

    async def send(self, text: str) -> None:
        await self.websocket.send(text)
