"""Each robot of a cell its own recording (issue 30.7), and `record NAME all` for every robot.

A real cell of two robots, each on its own port: a connection records its robot
only, cannot stop the other robot's recording, and both record at once; `record NAME
all` records both into NAME.ROBOT.txt/.csv/.html and one bag whose topics and frames
carry each robot's name, placed in the cell's `world` frame.
"""

from __future__ import annotations

import asyncio
import csv
import threading
from collections.abc import Iterator
from concurrent.futures import Future
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin
import pytest
from rosbags.highlevel import AnyReader
from support import Client, load_robot

from c2rviz.app.program import write_page
from c2rviz.clients import player
from c2rviz.observers.bag_topics import namespaces
from c2rviz.session import ServerLimits, Services
from c2rviz.transports.tcp_server import CommandServer
from c2rviz.world.observer import RecordingScene
from c2rviz.world.world import World

LEFT_ORIGIN = pin.SE3(pin.rpy.rpyToMatrix(0, 0, 0.3), np.array([0.0, 0.6, 0.0]))
RIGHT_ORIGIN = pin.SE3(pin.rpy.rpyToMatrix(0, 0, -0.3), np.array([0.0, -0.6, 0.0]))


class Cell:
    """A live cell (motoman `left`, fanuc `right`) on its own loop and thread."""

    def __init__(self, folder: Path) -> None:
        self.loop = asyncio.new_event_loop()
        self.scene = RecordingScene()
        robots = {"left": load_robot("motoman_sia20d"), "right": load_robot("fanuc_lrmate200id")}
        self.world = World(robots, self.scene, origins={"left": LEFT_ORIGIN, "right": RIGHT_ORIGIN})
        self.services = Services(
            self.world, limits=ServerLimits(), record_dir=folder, exporters=(write_page,)
        )
        self.servers = [CommandServer(self.services, robot=name) for name in robots]
        self.thread = threading.Thread(target=self.loop.run_forever, daemon=True)
        self.thread.start()
        self.ports = {
            name: self.run(server.start("127.0.0.1", 0))[1]
            for name, server in zip(robots, self.servers)
        }

    def run(self, coro: Any) -> Any:
        return asyncio.run_coroutine_threadsafe(coro, self.loop).result(timeout=60)

    def call(self, fn: Any) -> Any:
        done: Future[Any] = Future()
        self.loop.call_soon_threadsafe(lambda: done.set_result(fn()))
        return done.result(timeout=60)

    def stop(self) -> None:
        for server in self.servers:
            self.run(server.stop())
        self.loop.call_soon_threadsafe(self.loop.stop)
        self.thread.join(timeout=60)
        self.loop.close()


@pytest.fixture
def cell(tmp_path: Path) -> Iterator[Cell]:
    running = Cell(tmp_path)
    yield running
    running.stop()


@pytest.fixture
def clients(cell: Cell) -> Iterator[dict[str, Client]]:
    opened = {name: Client("127.0.0.1", port) for name, port in cell.ports.items()}
    yield opened
    for client in opened.values():
        client.close()


def topics(bag: Path) -> dict[str, list[Any]]:
    out: dict[str, list[Any]] = {}
    with AnyReader([bag]) as reader:
        for conn, log_ns, raw in reader.messages():
            out.setdefault(conn.topic, []).append((log_ns, reader.deserialize(raw, conn.msgtype)))
    return out


def test_each_robot_has_its_own_recording(cell: Cell, clients: dict[str, Client], tmp_path: Path):
    left, right = clients["left"], clients["right"]
    assert left.ask("record l") == f"ok recording l into {tmp_path.resolve()}"
    assert right.ask("record") == "ok not recording"
    # Another robot's connection cannot stop it.
    assert right.ask("record stop") == (
        "error: record: robot right is not being recorded; l (robot left) can be stopped only "
        "from a connection driving its robot ('robot NAME' chooses)"
    )
    assert right.ask("record l").startswith("error: record: l is being recorded (robot left)")
    assert right.ask("record r") == f"ok recording r into {tmp_path.resolve()}"
    assert left.ask("move 0 0.4") == "ok"
    assert right.ask("move 1 -0.3") == "ok"
    assert left.ask("sleep 0.05") == "ok"
    assert left.ask("record stop").startswith("ok recorded l: ")
    assert right.ask("record").startswith("ok recording r ")
    assert right.ask("record stop").startswith("ok recorded r: ")
    assert left.ask("record stop") == "error: record: nothing is being recorded"
    names = sorted(p.name for p in tmp_path.iterdir())
    assert names == ["l", "l.csv", "l.html", "l.txt", "r", "r.csv", "r.html", "r.txt"]
    assert player.load_script(tmp_path / "l.txt").robot == "motoman_sia20d"
    assert player.load_script(tmp_path / "r.txt").robot == "fanuc_lrmate200id"
    # Each bag holds its robot alone, namespaced as in the cell and placed in it.
    bag = topics(tmp_path / "l")
    assert {t for t in bag if "joint_states" in t or "robot_description" in t} == {
        "/left/joint_states",
        "/left/robot_description",
    }
    (placed,) = [x for x in bag["/tf_static"][-1][1].transforms if x.header.frame_id == "world"]
    assert placed.child_frame_id == "left/base_link"
    t = placed.transform.translation
    np.testing.assert_allclose([t.x, t.y, t.z], LEFT_ORIGIN.translation, atol=1e-12)
    assert bag["/left/joint_states"][-1][1].position[0] == pytest.approx(0.4, abs=1e-12)


def test_record_all_records_every_robot_at_once(
    cell: Cell, clients: dict[str, Client], tmp_path: Path
):
    left, right = clients["left"], clients["right"]
    assert right.ask("record both all") == f"ok recording both into {tmp_path.resolve()}"
    assert left.ask("record").startswith("ok recording both ")
    assert left.ask("record x").startswith("error: record: both is being recorded (")
    assert left.ask("mark") == "ok"
    for line in ("motion on", "speed 100"):
        assert left.ask(line) == right.ask(line) == "ok"
    left.send("joints 0.3,0.2,0,0,0,0,0\n")
    right.send("joints -0.3,0.1,0.1,0,0,0\n")
    assert left.read_line() == right.read_line() == "ok"
    for k in range(20):  # a flood within frames: the latest state of each frame is kept
        assert left.ask(f"move 0 {0.3 + k / 1000}") == "ok"
    assert right.ask("sleep 0.05") == "ok"
    reply = left.ask("record stop")  # either robot's connection stops the whole
    assert reply.startswith("ok recorded both: both.left ") and "both.right " in reply
    assert right.ask("record") == "ok not recording"
    names = sorted(p.name for p in tmp_path.iterdir())
    assert names == [
        "both",
        *(f"both.{robot}.{ext}" for robot in ("left", "right") for ext in ("csv", "html", "txt")),
    ]
    bag = topics(tmp_path / "both")
    assert {"/left/joint_states", "/right/joint_states"} <= set(bag)
    stamps = [ns for ns, _ in bag["/tf"]]
    assert stamps == sorted(stamps)  # the cell's /tf in time order
    for robot, topic in (("left", "/left/joint_states"), ("right", "/right/joint_states")):
        with open(tmp_path / f"both.{robot}.csv", newline="") as file:
            rows = list(csv.reader(file))[1:]
        assert [f"{ns / 1e9:.6f}" for ns, _ in bag[topic]] == [row[0] for row in rows]
        frames = {x.child_frame_id.split("/")[0] for _, tf in bag["/tf"] for x in tf.transforms}
        assert frames == {"left", "right"}
    (marker,) = [m for _, a in bag["/left/visualization_marker_array"] for m in a.markers]
    assert marker.header.frame_id == "world"
    placed = {
        x.child_frame_id: x for x in bag["/tf_static"][-1][1].transforms
        if x.header.frame_id == "world"
    }  # fmt: skip
    assert set(placed) == {"left/base_link", "right/base_link"}


@pytest.mark.parametrize(
    ("names", "spaces"),
    [
        (["left", "right"], ["left", "right"]),
        (["arm-1", "arm.2", "2nd", "_x"], ["arm_1", "arm_2", "r2nd", "r_x"]),
        (["a-b", "a_b", "a b"], ["a_b", "a_b_2", "a_b_3"]),
    ],
)
def test_each_robot_gets_a_ros_namespace(names: list[str], spaces: list[str]) -> None:
    assert list(namespaces(names).values()) == spaces
