"""Property tests: whatever arrives, the parser and the live server behave.

The parser may only raise ``C2rvizError``s. The live server, fed arbitrary
bytes and near-miss commands, must answer exactly what a reference model (the
parser plus a ``Session`` on a shadow ``World``) predicts, and end in exactly
the state the model ends in: a line that is not a valid command changes nothing.
"""

from __future__ import annotations

import contextlib
import math
import socket

import numpy as np
import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st
from support import ServerThread, examples, load_robot

from c2rviz.app.config import ServerLimits
from c2rviz.errors import C2rvizError, LineTooLong
from c2rviz.protocol import replies
from c2rviz.protocol.grammar import ForeignProtocol, parse_line
from c2rviz.protocol.verbs.seed import Bye, Quit, Sleep
from c2rviz.session import Services, Session
from c2rviz.world.world import World

VERBS = [
    "rand", "home", "degrees", "degree", "radians", "radian", "joints", "j", "move", "clear",
    "mark", "color", "rgb", "marker", "where", "pose", "names", "help", "sleep", "bye",
    "jump", "GET", "Host:", "",
]  # fmt: skip
ODD_NUMBERS = [
    "nan", "NaN", "inf", "-Infinity", "1e309", "-1e400", "0x10", "1_0", "1.5abc", "", ".",
    "\u0661", "\uff11", "+.5", "1.", "-0", "1e-3", "--1", "1e", "9" * 30, "cube", "sphere",
]  # fmt: skip

number_text = st.one_of(
    st.floats(-3.5, 3.5).map(lambda v: f"{v:.4g}"),  # mostly inside the limits [rad]
    st.integers(0, 9).map(str),  # joint indices, valid and not
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.sampled_from(ODD_NUMBERS),
)
argument = st.lists(number_text, min_size=1, max_size=8).map(",".join)
verb = st.sampled_from(VERBS).flatmap(lambda v: st.sampled_from([v, v.upper(), v.capitalize()]))
separator = st.sampled_from([" ", "  ", "\t", " , ", ","])
tail = st.sampled_from(["", "", "\r", " # note", "\x00", "\x1b", " \u00e9"])


@st.composite
def near_miss_line(draw: st.DrawFn) -> str:
    """A line shaped like a command: a verb, some comma lists, odd separators and tails."""
    words = [draw(verb), *draw(st.lists(argument, max_size=3))]
    text = words[0]
    for word in words[1:]:
        text += draw(separator) + word
    return draw(st.sampled_from(["", " ", "\t"])) + text + draw(tail)


inside = st.floats(-1.9, 1.9).map(lambda v: f"{v:.6g}")  # within every motoman joint's limits


@st.composite
def valid_line(draw: st.DrawFn) -> str:
    """A well-formed command, mostly one that changes the state."""
    kind = draw(st.sampled_from(["move", "joints", "mark", "other"]))
    if kind == "move":
        indices = draw(st.lists(st.integers(0, 6), min_size=1, max_size=7, unique=True))
        values = [draw(inside) for _ in indices]
        return f"move {','.join(map(str, indices))} {','.join(values)}"
    if kind == "joints":
        return "joints " + ",".join(draw(st.lists(inside, min_size=7, max_size=7)))
    if kind == "mark":
        return "mark " + ",".join(draw(st.lists(inside, min_size=6, max_size=6)))
    return draw(
        st.sampled_from(["home", "rand", "clear", "mark", "degrees", "radians", "where", "pose",
                         "color 0,1,0.5", "marker cube", "sleep 0"])
    )  # fmt: skip


lines_of_bytes = st.lists(
    st.one_of(
        valid_line().map(str.encode),
        valid_line().map(str.encode),  # twice: half the lines are commands that should work
        near_miss_line().map(str.encode),
        st.binary(max_size=300),
    ),
    min_size=1,
    max_size=6,
)


# The parser alone


@settings(max_examples=examples(500), deadline=None)
@given(st.one_of(st.text(), near_miss_line()))
def test_the_parser_raises_only_our_errors(line):
    try:
        command = parse_line(line)
    except C2rvizError as exc:
        assert "\n" not in str(exc)  # an error is one reply line
        return
    values = getattr(command, "values", None) or getattr(command, "pose", None) or ()
    assert all(math.isfinite(v) for v in values)


@settings(max_examples=examples(500), deadline=None)
@given(st.binary())
def test_the_parser_takes_any_decoded_bytes(data):
    for raw in data.split(b"\n"):
        with contextlib.suppress(C2rvizError):
            parse_line(raw.decode("utf-8", "surrogateescape"))


# The live server against a reference model

MAX_LINE = 256
LIMITS = ServerLimits(max_line=MAX_LINE, max_sleep_s=0.02)


@pytest.fixture(scope="module")
def live():
    """One server for the module, small limits so they are reached, and a bystander."""
    server = ServerThread(load_robot(), LIMITS).start()
    bystander = socket.create_connection((server.host, server.port), timeout=10)
    stream = bystander.makefile("rwb", buffering=0)
    yield server, stream
    stream.close()
    bystander.close()
    server.stop()


def predict(data: bytes, session: Session) -> tuple[list[str], bool]:
    """The replies to ``data`` (complete lines) and whether the server closes after them."""
    out: list[str] = []
    for raw in data.split(b"\n")[:-1]:
        if len(raw) > MAX_LINE:
            return [*out, replies.error(LineTooLong(MAX_LINE))], True
        try:
            command = parse_line(raw.decode())
        except UnicodeDecodeError:
            out.append("error: " + replies.NOT_UTF8)
            continue
        except ForeignProtocol:  # an HTTP 400, read here line by line
            return [*out, *replies.not_http(None).decode().split("\n")[:-1]], True
        except C2rvizError as exc:
            out.append(replies.error(exc))
            continue
        if command is None:
            continue
        if isinstance(command, Quit):
            raise AssertionError("the strategies never send quit")
        if isinstance(command, Bye):
            return [*out, replies.BYE], True
        if isinstance(command, Sleep):
            over = command.seconds > LIMITS.max_sleep_s
            out.append("error: sleep: " if over else "ok")  # the server builds the first
            continue
        try:
            out.append(session.execute(command))
        except C2rvizError as exc:
            out.append(replies.error(exc))
    return out, False


def read_replies(sock: socket.socket, count: int, closes: bool) -> list[str]:
    with sock.makefile("rb") as stream:
        got = [stream.readline().decode().rstrip("\n") for _ in range(count)]
        if closes:
            assert stream.read() == b""
    return got


@settings(
    max_examples=examples(200),
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow],
)
@given(lines=lines_of_bytes, seed=st.integers(0, 2**32 - 1))
def test_the_server_does_what_the_model_predicts(live, lines, seed):
    server, bystander = live
    world = server.world
    # A shadow world in the server's state, with the same random stream for `rand`.
    shadow = World(world.robot)
    q, markers = server.call(lambda: (world.q, list(world.markers)))
    shadow.set_q(q)
    shadow.markers.extend(markers)
    server.call(lambda: setattr(server.services, "rng", np.random.default_rng(seed)))
    data = b"\n".join(line.replace(b"\n", b"") for line in lines) + b"\n"
    expected, closes = predict(data, Session(Services(shadow, rng=np.random.default_rng(seed))))
    event(f"closes={closes}")
    event(f"ok replies: {min(sum(r.startswith('ok') for r in expected), 3)}")
    event(f"state changed: {shadow.q != q or shadow.markers != markers}")

    with socket.create_connection((server.host, server.port), timeout=30) as sock:
        sock.sendall(data if closes else data + b"names\n")
        got = read_replies(sock, len(expected) + (not closes), closes)

    if not closes:
        assert got.pop() == replies.ok(f"{world.robot.name} {','.join(world.robot.joint_names)}")
    assert len(got) == len(expected)
    for reply, want in zip(got, expected):
        assert reply.startswith(want) if want == "error: sleep: " else reply == want
    assert server.call(lambda: (world.q, world.markers)) == (shadow.q, shadow.markers)
    bystander.write(b"where\n")
    assert bystander.readline().decode() == replies.ok(replies.numbers(shadow.q)) + "\n"
