"""What the view adapter and its door cost, next to viser's own ways.

Prints, on this machine:

* a send: Pinocchio FK and every link frame's pose plus every slider's value,
  through ``adapter.queue_pose``/``set_gui_value`` and through viser's public
  setters (``handle.position = ...``, ``slider.value = ...``) [ms];
* the door's screen of one inbound frame (a slider value, a camera update,
  junk) [us];
* ``purge_removed`` with 1000 live markers and N removal records [ms], and the
  broadcast buffer after 60k marker add/remove cycles, purged every 1000 or not;
* stopping viser with a tab that never reads: ``adapter.stop`` and viser's own
  ``stop`` [s].

Run: ``PYTHONPATH=. python benchmarks/view_bench.py`` (about 30 s).
"""

from __future__ import annotations

import contextlib
import io
import logging
import socket
import sys
import time
import timeit
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import msgspec
import numpy as np
import pinocchio as pin
import viser

from c2rviz.robot.model import Robot
from c2rviz.view import adapter
from c2rviz.view.door_rules import DoorPolicy

ROOT = Path(__file__).resolve().parent.parent


def _wxyz(rotation: np.ndarray) -> np.ndarray:
    x, y, z, w = pin.Quaternion(rotation).coeffs()
    return np.array([w, x, y, z])


def best_of(fn: Callable[[], object], number: int, repeat: int = 5) -> float:
    """Best mean time of one call [s]."""
    return min(timeit.repeat(fn, number=number, repeat=repeat)) / number


def send_cost(server: viser.ViserServer) -> None:
    robot = Robot.from_urdf(ROOT / "robots/motoman_sia20d/robot.urdf", "base_link", "link_t")
    data = robot.model.createData()
    frames = [
        (robot.model.getFrameId(link, pin.BODY), server.scene.add_frame(f"/robot/{link}"))
        for link in robot.link_names()
    ]
    sliders = [
        server.gui.add_slider(j.name, min=-360.0, max=360.0, step=0.1, initial_value=0.0)
        for j in robot.joints
    ]
    for slider in sliders:
        slider.on_update(lambda event: None)  # as the viewer's: a callback per slider
    rng = np.random.default_rng(0)
    poses = [robot.random(rng) for _ in range(64)]
    turn = [0]

    def send(fast: bool) -> None:
        q = poses[turn[0] % len(poses)]
        turn[0] += 1
        pin.forwardKinematics(robot.model, data, robot.configuration(q))
        pin.updateFramePlacements(robot.model, data)
        with server.atomic():
            for frame_id, handle in frames:
                placement = data.oMf[frame_id]
                if fast:
                    adapter.queue_pose(handle, placement.translation, _wxyz(placement.rotation))
                else:
                    handle.position = placement.translation
                    handle.wxyz = _wxyz(placement.rotation)
            for slider, value in zip(sliders, np.degrees(q)):
                if fast:
                    adapter.set_gui_value(slider, round(float(value), 6))
                else:
                    slider.value = round(float(value), 6)
        server.flush()

    print(f"send ({len(frames)} link frames, {len(sliders)} sliders, FK included):")
    for name, fast in (("adapter", True), ("public setters", False)):
        print(f"  {name:16s} {best_of(lambda fast=fast: send(fast), 200) * 1e3:7.3f} ms")


def screen_cost(server: viser.ViserServer) -> None:
    logging.getLogger("c2rviz.view").setLevel(logging.ERROR)  # the junk frames are logged
    slider = server.gui.add_slider("bench", min=0.0, max=1.0, step=0.1, initial_value=0.5)
    adapter.accept_input(server, slider, lambda client_id, value: None)
    door = adapter.door(server)
    camera = {
        "type": "ViewerCameraMessage",
        **{"wxyz": [1.0, 0.0, 0.0, 0.0], "position": [1.0, 2.0, 3.0], "fov": 1.0},
        **{"near": 0.01, "far": 100.0, "image_height": 700, "image_width": 1000},
        **{"look_at": [0.0, 0.0, 0.0], "up_direction": [0.0, 0.0, 1.0]},
    }
    frames = {
        "slider value": {
            "type": "GuiUpdateMessage",
            "uuid": slider._impl.uuid,
            "updates": {"value": 0.3},
        },
        "camera update": camera,
        "unknown message": {"type": "FileTransferPart", "transfer_uuid": "t", "content": b""},
        "60k empty arrays": [[]] * 60_000,
        "60k in a field": {"junk": [[]] * 60_000, "type": "ViewerCameraMessage"},
    }
    print("door screen of one inbound frame:")
    for name, message in frames.items():
        frame = msgspec.msgpack.encode(message)
        cost = best_of(lambda frame=frame: door.screen(None, frame), 2000)  # type: ignore[arg-type]
        print(f"  {name:18s} {len(frame):6d} B {cost * 1e6:8.2f} us")


def purge_cost(server: viser.ViserServer) -> None:
    scene = server.scene
    for i in range(1000):
        scene.add_icosphere(f"/live/m{i}", radius=0.01)
    print("purge_removed with 1000 live markers:")
    serial = 0
    for records in (0, 1000, 10_000):
        for _ in range(records):
            serial += 1
            scene.add_icosphere(f"/gone/m{serial}", radius=0.01).remove()
        start = time.perf_counter()
        adapter.purge_removed(server)
        cost = time.perf_counter() - start
        print(f"  {records:6d} removal records: {cost * 1e3:7.2f} ms")
    print("broadcast buffer after 60k marker add/remove cycles (messages):")
    for every in (None, 1000):
        base = adapter.buffered_messages(server)
        for i in range(60_000):
            serial += 1
            scene.add_icosphere(f"/gone/m{serial}", radius=0.01).remove()
            if every and i % every == every - 1:
                adapter.purge_removed(server)
        grown = adapter.buffered_messages(server) - base
        print(f"  purged every {every or 'never':>5}: +{grown}")
        adapter.purge_removed(server)


def never_reading_tab(port: int) -> socket.socket:
    sock = socket.socket()
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
    sock.connect(("127.0.0.1", port))
    sock.sendall(
        (
            f"GET / HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nUpgrade: websocket\r\n"
            "Connection: Upgrade\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n"
            f"Sec-WebSocket-Version: 13\r\nSec-WebSocket-Protocol: viser-v{viser.__version__}"
            "\r\n\r\n"
        ).encode()
    )
    head = b""
    while b"\r\n\r\n" not in head:
        head += sock.recv(1)
    return sock


def stop_cost() -> None:
    print("stop with a tab that never reads (12 MB unsent):")
    points = np.random.default_rng(1).random((1_000_000, 3), dtype=np.float32)

    def viser_stop(server: viser.ViserServer) -> None:
        with contextlib.redirect_stdout(io.StringIO()):
            server.stop()

    def start_viser() -> viser.ViserServer:
        with contextlib.redirect_stdout(io.StringIO()):
            return viser.ViserServer(host="127.0.0.1", port=0, verbose=False)

    runs: Sequence[tuple[str, Callable[[], Any], Callable[[Any], object]]] = (
        ("adapter.stop", lambda: adapter.start("127.0.0.1", 0), adapter.stop),
        ("viser's stop", start_viser, viser_stop),
    )
    for name, begin, end in runs:
        server = begin()
        tab = never_reading_tab(server.get_port())
        time.sleep(0.2)
        server.scene.add_point_cloud("/cloud", points, colors=(1.0, 0.0, 0.0))
        server.flush()
        time.sleep(0.5)  # viser's send blocks on the full TCP window
        start = time.perf_counter()
        end(server)
        print(f"  {name:14s} {time.perf_counter() - start:6.2f} s")
        tab.close()


def main(argv: Sequence[str] | None = None) -> int:
    del argv
    print(f"viser {viser.__version__}, python {sys.version.split()[0]}")
    server = adapter.start("127.0.0.1", 0, policy=DoorPolicy())
    try:
        send_cost(server)
        screen_cost(server)
        purge_cost(server)
    finally:
        adapter.stop(server)
    stop_cost()
    return 0


if __name__ == "__main__":
    sys.exit(main())
