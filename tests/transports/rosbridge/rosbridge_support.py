"""A real rosbridge server on 127.0.0.1:0 in front of a small in-test Bridge (test support).

``CounterBridge`` is what the tests talk to through the server: it publishes a
counter topic (``/counter``, messages made when a test calls ``tick``) and a
latched one (``/latched``), takes ``/inbox`` (std_msgs/String) and
``/joint_command`` (sensor_msgs/JointState, checked by ``messages``), and
answers the service ``/c2rviz/command``. Everything it is given lands in
thread-safe queues the tests wait on. The server runs on its own event loop in
a thread, so the tests are plain functions that talk to it as clients would:
roslibpy, or a raw websockets client.
"""

from __future__ import annotations

import asyncio
import queue
import threading
from collections.abc import Callable, Coroutine
from concurrent.futures import Future
from typing import Any

from c2rviz.errors import C2rvizError
from c2rviz.transports.rosbridge import (
    COMMAND_SERVICE_TYPE,
    RosbridgePolicy,
    RosbridgeServer,
    command_request,
    command_response,
    joint_positions,
    string_data,
)

WAIT_S = 20.0  # generous: the machine is shared; a passing test never waits this long


class CounterBridge:
    """A Bridge with a counter topic, a latched topic, two taken topics and one service."""

    TOPICS = (
        ("/counter", "std_msgs/msg/String"),
        ("/latched", "std_msgs/String"),
        ("/inbox", "std_msgs/msg/String"),
        ("/joint_command", "sensor_msgs/msg/JointState"),
    )

    def __init__(self) -> None:
        self.count = 0
        self.latched: dict[str, Any] = {"data": "latched hello"}
        self.deliveries: dict[object, tuple[str, Callable[[dict[str, Any]], None]]] = {}
        self.subscribed: queue.Queue[str] = queue.Queue()
        self.unsubscribed: queue.Queue[str] = queue.Queue()
        self.published: queue.Queue[tuple[str, str, Any]] = queue.Queue()
        self.calls: queue.Queue[str] = queue.Queue()
        self.sources: queue.Queue[tuple[str, str]] = queue.Queue()
        self.changes = False
        self.release = asyncio.Event()  # a service call "hold" waits for it (set on the loop)
        self.release.set()

    def topics(self) -> list[tuple[str, str]]:
        return list(self.TOPICS)

    def services(self) -> list[tuple[str, str]]:
        return [("/c2rviz/command", COMMAND_SERVICE_TYPE)]

    def trajectory_joints(self) -> dict[str, tuple[str, ...]]:
        return {}

    def params(self) -> dict[str, object]:
        return {"robot_description": "<robot name='counter'/>"}

    def opened(self, source: str) -> None:
        self.sources.put(("opened", source))

    def closed(self, source: str) -> None:
        self.sources.put(("closed", source))

    def hang_up_with(self, hang_up: Callable[[str], None]) -> None:
        self.hang_up = hang_up

    def subscribe(self, topic: str, deliver: Callable[[dict[str, Any]], None]) -> object:
        if topic not in ("/counter", "/latched"):
            raise C2rvizError(f"{topic} is not published here")
        handle = object()
        self.deliveries[handle] = (topic, deliver)
        if topic == "/latched":
            deliver(self.latched)
        self.subscribed.put(topic)
        return handle

    def snapshot(self, topic: str) -> dict[str, Any] | None:
        """With ``changes`` set, /counter's messages count as changes: its whole state."""
        return {"data": f"all {self.count}"} if self.changes and topic == "/counter" else None

    def unsubscribe(self, handle: object) -> None:
        entry = self.deliveries.pop(handle, None)
        if entry is not None:
            self.unsubscribed.put(entry[0])

    def tick(self, times: int = 1, pad: int = 0) -> None:
        """Publish the next ``times`` counter values (on the server's loop), ``pad`` bytes more."""
        for _ in range(times):
            self.count += 1
            msg = {"data": str(self.count) + " " * pad}
            for topic, deliver in list(self.deliveries.values()):
                if topic == "/counter":
                    deliver(msg)

    async def publish(self, source: str, topic: str, msg: dict[str, Any]) -> None:
        if topic == "/inbox":
            self.published.put((source, topic, string_data(msg)))
        elif topic == "/joint_command":
            self.published.put((source, topic, joint_positions(msg)))
        else:
            raise C2rvizError(f"c2rviz does not take {topic} (it takes /inbox, /joint_command)")

    async def call_service(self, source: str, service: str, args: dict[str, Any]) -> dict[str, Any]:
        line = command_request(args)
        self.calls.put(line)
        if line == "hold":
            await self.release.wait()
        if line.startswith("fail"):
            raise C2rvizError(f"{line}: refused on purpose")
        return command_response(f"did {line}", True)


class ServerThread:
    """A ``RosbridgeServer`` on its own event loop in a daemon thread."""

    def __init__(self, bridge: CounterBridge, policy: RosbridgePolicy) -> None:
        self.bridge = bridge
        self.loop = asyncio.new_event_loop()
        self.server = RosbridgeServer(bridge, policy)
        self.thread = threading.Thread(target=self.loop.run_forever, daemon=True)
        self.thread.start()
        self.host, self.port = self.run(self.server.start("127.0.0.1", 0))
        self.url = f"ws://127.0.0.1:{self.port}/"

    def run(self, coroutine: Coroutine[Any, Any, Any]) -> Any:
        """Run ``coroutine`` on the server's loop and return its result."""
        return asyncio.run_coroutine_threadsafe(coroutine, self.loop).result(WAIT_S)

    def call(self, fn: Callable[..., Any], *args: Any) -> Any:
        """Call ``fn(*args)`` on the server's loop and return its result."""
        done: Future[Any] = Future()

        def call() -> None:
            try:
                done.set_result(fn(*args))
            except BaseException as error:
                done.set_exception(error)

        self.loop.call_soon_threadsafe(call)
        return done.result(WAIT_S)

    def stop(self) -> None:
        self.run(self.server.stop())
        self.loop.call_soon_threadsafe(self.loop.stop)
        self.thread.join(WAIT_S)
        self.loop.close()
