"""``Client`` and ``AsyncClient`` against a real server: every verb, typed results, and what
goes wrong (an ``error:`` reply, a bad argument, a server gone mid-call).
"""

from __future__ import annotations

import asyncio
import inspect
import math
import threading
import time
from dataclasses import dataclass
from pathlib import Path

import pytest
from support import typed_verbs

from c2rviz import AsyncClient, Client, CommandError, ConnectionLost, Event, JointLimit, Pose, State
from c2rviz.clients.errors import ArgumentError, ArgumentTypeError
from c2rviz.clients.records import MotionStatus, RobotNames, TrailStatus
from c2rviz.errors import BadArguments
from c2rviz.protocol import replies
from c2rviz.protocol.registry import HANDLERS, LOOKUP, VERBS, handler, usage, verb


@pytest.mark.parametrize("cls", [Client, AsyncClient], ids=["Client", "AsyncClient"])
def test_every_typed_method_speaks_a_verb_of_the_registry(cls):
    typed = typed_verbs(cls)
    assert typed, f"{cls.__name__} has no method tagged @speaks(verb)"
    assert set(typed) <= set(VERBS), "a method speaks a verb the registry does not know"
    assert typed == typed_verbs(Client), "the two clients type different verbs"


@pytest.fixture
def a_verb_with_no_method():
    """A verb registered for this test alone, entry and handler, as a new verb would be
    (and taken out again): the clients have no typed method for it."""

    @verb("echo_words", "WORD...", "reply the words", examples=("echo_words a B c",))
    @dataclass(frozen=True)
    class EchoWords:
        words: tuple[str, ...]

        @staticmethod
        def parse(verb: str, words: list[str]) -> EchoWords:
            if not words:
                raise BadArguments(verb, "needs a word", usage(verb))
            return EchoWords(tuple(words))

    @handler(EchoWords)
    def echo_words(session: object, command: EchoWords) -> str:
        return replies.ok(" ".join(command.words))

    yield VERBS["echo_words"]
    del VERBS["echo_words"], LOOKUP["echo_words"], HANDLERS[EchoWords]


def test_a_verb_with_no_typed_method_is_a_method_by_name_of_both_clients(
    server, a_verb_with_no_method
):
    """Every verb of the registry without a typed method (here at least the test's own)
    is ``robot.VERB(*words)`` in both clients: each of its examples, sent by name, gets
    the reply that ``send`` gets for the line."""
    untyped = [v for v in VERBS.values() if v.name not in typed_verbs(Client)]
    assert a_verb_with_no_method in untyped
    sent = [(v.name, line, line.split()[1:]) for v in untyped for line in v.examples]
    assert len(sent) >= len(untyped)  # every verb has an example (test_registry asks)
    with Client(server.host, server.port) as robot:
        assert robot.echo_words("a", "B", 3) == "ok a B 3"
        for name, line, words in sent:
            assert getattr(robot, name)(*words) == robot.send(line), line
        with pytest.raises(CommandError, match="echo_words: needs a word"):
            robot.echo_words()  # an error reply raises, as from send
        with pytest.raises(AttributeError):
            robot.no_such_verb  # noqa: B018 (a name the registry lacks is no method)

    async def main() -> None:
        async with AsyncClient(server.host, server.port) as robot:
            assert await robot.echo_words("x") == "ok x"
            for name, line, words in sent:
                assert await getattr(robot, name)(*words) == await robot.send(line), line
            with pytest.raises(AttributeError):
                robot.no_such_verb  # noqa: B018

    asyncio.run(main())


def test_the_async_client_mirrors_the_blocking_one():
    public = {
        name
        for name, member in inspect.getmembers(Client, inspect.isfunction)
        if not name.startswith("_") and name not in ("post", "read_reply", "alive", "ask")
    }
    for name in sorted(public):
        mirror = getattr(AsyncClient, name, None)
        assert mirror is not None, f"AsyncClient has no {name}"
        if name != "watch":  # a stream of its own, to iterate with async for
            assert inspect.iscoroutinefunction(mirror), f"AsyncClient.{name} is not async"
        want = inspect.signature(getattr(Client, name))
        assert inspect.signature(mirror).parameters == want.parameters, name


def test_every_method_says_its_units():
    """A method that takes or gives angles or lengths names the unit in its docstring."""
    for spoken, names in typed_verbs(Client).items():
        for name in names:
            doc = getattr(Client, name).__doc__ or ""
            signature = str(inspect.signature(getattr(Client, name)))
            if any(word in signature for word in ("float", "Pose", "JointLimit")):
                assert "[" in doc, f"{name} ({spoken}) states no unit"


def same_pose(a: Pose, b: Pose) -> bool:
    """Equal poses within 1e-6 (m, rad), an angle of pi the same as -pi."""
    turns = [(x - y + math.pi) % (2 * math.pi) - math.pi for x, y in zip(a[3:], b[3:])]
    return a[:3] == pytest.approx(b[:3], abs=1e-6) and turns == pytest.approx([0] * 3, abs=1e-6)


@pytest.fixture
def robot(server):
    with Client(server.host, server.port) as client:
        yield client


def test_questions_come_back_typed(robot):
    assert robot.names() == RobotNames(
        "motoman_sia20d",
        ("joint_s", "joint_l", "joint_e", "joint_u", "joint_r", "joint_b", "joint_t"),
    )
    assert robot.where() == (0.0,) * 7
    pose = robot.pose()
    assert isinstance(pose, Pose) and pose.z > 1.0
    limits = robot.limits()
    assert all(isinstance(limit, JointLimit) and limit.unit == "rad" for limit in limits)
    lower, upper, unit = limits[0]  # a (lower, upper, unit) triple, as before
    assert lower < 0 < upper and unit == "rad"
    rates = robot.motion_limits()
    assert len(rates) == 7 and all(0 < r.velocity < r.acceleration < r.jerk for r in rates)
    version = robot.version()
    assert version.robot_file == "robot.urdf" and len(version.sha256) == 12
    assert "where" in robot.help() and "joints|j v0,...,vn-1" in robot.help()
    assert robot.target() == (0.0,) * 7
    assert robot.status() == MotionStatus(False, 0.0)
    assert robot.robot() == "motoman_sia20d"
    assert robot.robots() == {"motoman_sia20d": None}  # (the program adds each port)


def test_moves_and_settings(robot, server):
    robot.joints([0.1, 0.2, 0, 0, 0, 0, 0])
    assert robot.where() == pytest.approx((0.1, 0.2, 0, 0, 0, 0, 0))
    robot.move([0, 2], [0.3, 0.4])
    assert robot.where()[:3] == pytest.approx((0.3, 0.2, 0.4))
    robot.move(1, [0.0])
    robot.degrees()
    assert robot.in_degrees and robot.where()[0] == pytest.approx(math.degrees(0.3))
    robot.radians()
    assert not robot.in_degrees
    robot.home()
    assert robot.where() == (0.0,) * 7
    robot.rand()
    assert robot.where() != (0.0,) * 7
    assert robot.speed(25) == 25.0 and robot.speed() == 25.0
    assert robot.speed(100) == 100.0  # the moves below on the real clock: no slower than needed
    assert robot.lspeed(0.1) == 0.1 and robot.lspeed() == 0.1
    assert robot.motion("on") == "on" and robot.motion() == "on"
    robot.home()  # on arrival
    assert robot.status() == MotionStatus(False, 0.0)
    robot.motion("follow")
    robot.joints([0.5, 0, 0, 0, 0, 0, 0])
    status = robot.status()
    assert status.moving and status.seconds_left > 0
    assert robot.target() == pytest.approx((0.5, 0, 0, 0, 0, 0, 0))
    robot.wait()
    assert robot.where() == pytest.approx((0.5, 0, 0, 0, 0, 0, 0))
    robot.joints([-0.5, 0, 0, 0, 0, 0, 0])
    robot.stop()
    assert not robot.status().moving
    robot.sleep(0.01)


def test_cartesian_markers_and_the_workcell(robot, server):
    tool = robot.tool([0, 0, 0.1, 0, 0, 0])
    assert tool == Pose(0, 0, 0.1, 0, 0, 0) and robot.tool() == tool
    robot.tool([0, 0, 0, 0, 0, 0])
    robot.joints([0.3, 0.5, 0, -1.0, 0, -0.6, 0])
    goal = robot.pose()
    robot.home()
    assert len(robot.ik(goal)) == 7  # one of many: the arm is redundant
    robot.moveto(goal)
    assert same_pose(robot.pose(), goal)
    aside = goal._replace(y=goal.y + 0.05)
    robot.movel(aside)
    assert same_pose(robot.pose(), aside)
    robot.color(0, 1, 0)
    robot.rgb(0, 0, 255)
    robot.marker("cube")
    robot.mark()
    robot.mark([0.4, 0, 1.0, 0, 0, 0])
    robot.mark([0.4, 0, 1.0, 0, 0, 0], world=True)
    robot.moveto(marker=1)
    robot.clear()
    robot.add_object("table", "box", [1, 1, 0.05], [0.7, 0, 0.5, 0, 0, 0])
    robot.add_object("ball", "sphere", 0.05, [0.5, 0.5, 0.5])
    robot.add_object("post", "cylinder", [0.05, 1], [0.5, -0.5, 0.5, 0, 0, 0])
    assert robot.objects() == ["table", "ball", "post"]
    assert robot.collisions() == []
    assert robot.guard(True) is True and robot.guard() is True
    with pytest.raises(CommandError, match="would hit table"):
        robot.joints([0, 1.2, 0, 1.2, 0, 1.0, 0])
    robot.guard(False)
    robot.joints([0, 1.2, 0, 1.2, 0, 1.0, 0])
    assert ("link_t", "table") in robot.collisions() or robot.collisions()
    robot.remove_object("ball")
    robot.remove_objects()
    assert robot.objects() == [] and robot.collisions() == []


@pytest.mark.wall_clock
def test_watching_trails_and_recording(robot, server, tmp_path):
    server.services.recordings.folder = tmp_path
    assert robot.recording() is None
    assert robot.record("take") == tmp_path.resolve()
    assert robot.recording().name == "take"
    robot.trail("on")
    assert robot.trail_status() == TrailStatus(True, robot.trail_status().points)
    with robot.watch(hz=50) as stream:
        records = iter(stream)
        first = next(records)
        assert isinstance(first, State) and first.values == (0.0,) * 7
        robot.motion("on")
        robot.joints([0.2, 0, 0, 0, 0, 0, 0])
        seen = []
        for record in records:
            seen.append(record)
            if isinstance(record, Event) and record.kind == "arrived":
                break
        assert any(isinstance(r, State) and r.values[0] > 0 for r in seen)
    robot.trail("clear")
    robot.trail("off")
    assert robot.trail_status() == TrailStatus(False, 0)
    done = robot.record_stop()
    assert done.name == "take" and done.frames > 2 and Path(done.files[0]).exists()
    robot.send("watch")
    robot.unwatch()


def test_send_sends_any_line_and_raises_on_errors(robot):
    assert robot.send("pose").startswith("ok ")
    assert robot.send("DEGREES # a comment") == "ok" and robot.in_degrees
    with pytest.raises(CommandError) as caught:
        robot.send("frobnicate 3")
    assert caught.value.message == "unknown command 'frobnicate' (try 'help')"
    assert caught.value.command == "frobnicate 3"
    with pytest.raises(ValueError, match="not a command"):
        robot.send("  # only a comment")


def test_an_error_reply_carries_the_servers_message(robot):
    with pytest.raises(CommandError) as caught:
        robot.joints([0, 9, 0, 0, 0, 0, 0])
    assert "joint_l (index 1) = 9 rad is outside its limits" in caught.value.message
    assert caught.value.reply.startswith("error: ")


@pytest.mark.parametrize(
    ("call", "kind", "words"),
    [
        (lambda r: r.joints("0,0,0"), ArgumentTypeError, "joints(values=...): expected a sequence"),
        (lambda r: r.joints([0, "1", 0, 0, 0, 0, 0]), ArgumentTypeError, "item 1 is a string"),
        (lambda r: r.joints([0, True, 0, 0, 0, 0, 0]), ArgumentTypeError, "item 1 is bool"),
        (lambda r: r.joints([0, 0, 0]), ArgumentError, "motoman_sia20d has 7 joints, 3 values"),
        (lambda r: r.joints([math.nan] * 7), ArgumentError, "item 0 (nan) is not a finite"),
        (lambda r: r.move([0, 9], [1, 2]), ArgumentError, "move(indices=...): joint 9"),
        (lambda r: r.move([0, 0], [1, 2]), ArgumentError, "an index is given twice"),
        (lambda r: r.move([0], [1, 2]), ArgumentError, "move(values=...): needs 1 values"),
        (lambda r: r.speed(150), ArgumentError, "speed(percent=...): 150 is outside 1..100"),
        (lambda r: r.speed("fast"), ArgumentTypeError, "speed(percent=...): expected a number"),
        (lambda r: r.moveto([1, 2, 3]), ArgumentError, "moveto(pose=...): needs 6 values"),
        (lambda r: r.moveto(), ArgumentError, "give a pose or marker=N"),
        (lambda r: r.motion("fast"), ArgumentError, "motion(mode=...): 'fast' is not one of"),
        (lambda r: r.guard("yes"), ArgumentTypeError, "guard(on=...): expected True or False"),
        (lambda r: r.sleep(-1), ArgumentError, "sleep(seconds=...): seconds must be >= 0"),
        (lambda r: r.color(2, 0, 0), ArgumentError, "channel 2 is outside 0..1"),
        (lambda r: r.marker("star"), ArgumentError, "'star' is not one of sphere"),
        (lambda r: r.robot("a b"), ArgumentError, "is not one plain word"),
        (lambda r: r.record("stop"), ArgumentError, "'stop' is not a name"),
        (lambda r: r.add_object("t", "cone", 1, [0, 0, 0]), ArgumentError, "'cone' is not one"),
        (lambda r: r.add_object("t", "box", [1, 0, 1], [0] * 6), ArgumentError, "above 0"),
        (lambda r: r.mark(None, world=True), ArgumentError, "world=True needs a pose"),
    ],
    ids=lambda value: value if isinstance(value, str) else None,
)
def test_a_bad_argument_raises_before_anything_is_sent(robot, server, call, kind, words):
    robot.where()  # connected, and `names` asked where a count needs it
    robot.names()
    before = list(server.scene.commands)
    with pytest.raises(kind) as caught:
        call(robot)
    assert words in str(caught.value)
    assert "nothing was sent" in str(caught.value)
    assert server.scene.commands == before  # not a line reached the server
    assert robot.where() == (0.0,) * 7  # and the connection is still in step


def test_a_server_gone_mid_call_raises_connection_lost_naming_the_command(c2rviz_process):
    process = c2rviz_process("--no-viewer")
    client = Client("127.0.0.1", process.port)
    client.sleep(0)
    process.popen.kill()
    with pytest.raises(ConnectionLost) as caught:
        client.sleep(30)
    assert isinstance(caught.value, ConnectionError)
    assert caught.value.command == "sleep 30.0"
    assert "while waiting for the reply to 'sleep 30.0'" in str(caught.value)


def test_a_server_stopped_mid_move_raises_connection_lost(start_server):
    """Issue 39, rough edge 4: docs/testing.md promises ConnectionLost; the server's
    `error: server is shutting down` raised a bare CommandError."""
    server = start_server()
    robot = Client(server.host, server.port)
    robot.motion("on")
    robot.speed(1)
    caught: list[BaseException] = []

    def move() -> None:
        try:
            robot.joints([1.5, 0, 0, 0, 0, 0, 0])
        except BaseException as exc:
            caught.append(exc)

    mover = threading.Thread(target=move)
    mover.start()
    with Client(server.host, server.port) as other:
        while not other.status().moving:
            time.sleep(0.01)
    server.stop()
    mover.join(60)
    (error,) = caught
    assert isinstance(error, ConnectionLost) and isinstance(error, ConnectionError)
    assert isinstance(error, CommandError)  # what caught it before still does
    assert (
        error.command == "joints 1.5,0.0,0.0,0.0,0.0,0.0,0.0"
        and error.message == "server is shutting down"
    )
    assert str(error) == (
        f"connection to {server.host}:{server.port} lost while waiting for the reply to "
        "'joints 1.5,0.0,0.0,0.0,0.0,0.0,0.0' (the server is shutting down)"
    )
    assert not robot.is_open  # the next call reconnects


def test_the_async_client_too_raises_connection_lost_at_shutdown(start_server):
    server = start_server()

    async def main() -> None:
        async with AsyncClient(server.host, server.port) as robot:
            await robot.motion("on")
            await robot.speed(1)
            move = asyncio.ensure_future(robot.joints([1.5, 0, 0, 0, 0, 0, 0]))
            async with AsyncClient(server.host, server.port) as other:
                while not (await other.status()).moving:
                    await asyncio.sleep(0.01)
            await asyncio.get_running_loop().run_in_executor(None, server.stop)
            with pytest.raises(ConnectionLost, match="the server is shutting down"):
                await move

    asyncio.run(main())


def test_the_client_drives_a_robot_of_a_cell_in_degrees(cell):
    with Client(cell.host, cell.port, robot="right", degrees=True) as right:
        assert right.names().robot == "right" and right.in_degrees
        right.joints([10, 0, 0, 0, 0, 0, 0])
        assert right.where()[0] == pytest.approx(10)
    with pytest.raises(CommandError, match="nonesuch"):
        Client(cell.host, cell.port, robot="nonesuch").open()


@pytest.fixture
def cell():
    from support import ServerThread, load_robot

    from c2rviz.session import ServerLimits

    robots = {"left": load_robot("motoman_sia20d"), "right": load_robot("kuka_lwr")}
    server = ServerThread(robots, ServerLimits()).start()  # type: ignore[arg-type]
    yield server
    server.stop()


@pytest.mark.wall_clock
def test_the_async_client(server):
    async def main() -> None:
        async with AsyncClient(server.host, server.port) as robot:
            assert (await robot.names()).joints[0] == "joint_s"
            await robot.motion("on")
            await robot.joints([0.2, 0, 0, 0, 0, 0, 0])
            assert (await robot.where())[0] == pytest.approx(0.2)
            await robot.degrees()
            assert robot.in_degrees
            assert await robot.send("radians") == "ok"
            assert not robot.in_degrees
            with pytest.raises(CommandError, match="unknown command"):
                await robot.send("frobnicate")
            with pytest.raises(ArgumentError, match="7 joints, 2 values"):
                await robot.joints([0, 0])
            async with robot.watch() as stream:
                async for record in stream:
                    assert isinstance(record, State) and record.values[0] == pytest.approx(0.2)
                    break
            # Two commands at once need two connections (sessions): the second stops the first.
            async with AsyncClient(server.host, server.port) as other:
                await robot.speed(5)
                move = asyncio.ensure_future(robot.joints([-1, 0, 0, 0, 0, 0, 0]))
                while not (await other.status()).moving:
                    await asyncio.sleep(0.01)
                await other.stop()
                with pytest.raises(CommandError, match="motion stopped by"):
                    await move

    asyncio.run(main())
