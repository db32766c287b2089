"""The viewer's door and viser adapter, against a real viser server and real websockets.

Each test starts viser through ``adapter.start`` on 127.0.0.1 port 0, with a
slider, a checkbox, a button and a scene frame, and talks to it as a page
does: a websocket with viser's subprotocol, msgpack frames out, viser's
zstd-compressed msgpack windows in.
"""

from __future__ import annotations

import ast
import logging
import socket
import threading
import time
import urllib.error
import urllib.request
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any
from urllib.parse import parse_qs, urlsplit

import msgspec
import numpy as np
import pytest
import viser
import zstandard
from viewer_tabs import bad_messages, gui_update, never_reading_tab
from websockets.exceptions import ConnectionClosed, InvalidStatus
from websockets.sync.client import ClientConnection, connect

from c2rviz.app.config import LIGHTINGS
from c2rviz.ini import normalize_origin
from c2rviz.view import adapter, viser_internals
from c2rviz.view.door_rules import DoorPolicy, DoorPolicyError, RateLimitedLog

VERSION = f"viser-v{viser.__version__}"
# the modules that reach inside viser: the adapter and the one it re-exports
ADAPTER_SOURCES = [
    Path(adapter.__file__).with_name(name) for name in ("adapter.py", "viser_internals.py")
]


def encode(message: dict[str, Any]) -> bytes:
    return msgspec.msgpack.encode(message)


def messages_in(frame: bytes | str) -> list[dict[str, Any]]:
    """The messages of one of viser's outgoing frames."""
    assert isinstance(frame, bytes)
    size = int.from_bytes(frame[:8], "little")
    compressed = int.from_bytes(frame[8:16], "little")
    inner = zstandard.ZstdDecompressor().decompress(frame[16 : 16 + compressed], size)
    return list(msgspec.msgpack.decode(inner)["messages"])


class Served:
    """A viser server started by the adapter, with inputs that record page values."""

    def __init__(self, policy: DoorPolicy | None = None, lighting: str = "studio") -> None:
        self.server = adapter.start("127.0.0.1", 0, label="test", policy=policy, lighting=lighting)
        self.port = self.server.get_port()
        self.door = adapter.door(self.server)
        gui = self.server.gui
        self.slider = gui.add_slider("slider", min=-10, max=10, step=0.1, initial_value=1.5)
        self.checkbox = gui.add_checkbox("checkbox", False)
        self.button = gui.add_button("button")
        self.frame = self.server.scene.add_frame("/frame", position=(0.1, 0.2, 0.3))
        self.calls: list[tuple[str, int, Any]] = []
        self.own_callbacks: list[str] = []  # viser's on_update: page input must never reach it
        self._changed = threading.Condition()
        self._sentinels = 0
        for name in ("slider", "checkbox", "button"):
            handle = getattr(self, name)
            adapter.accept_input(self.server, handle, self._recorder(name))
        self.slider.on_update(lambda event: self.own_callbacks.append("slider"))
        self.checkbox.on_update(lambda event: self.own_callbacks.append("checkbox"))
        self.button.on_click(lambda event: self.own_callbacks.append("button"))

    def _recorder(self, name: str) -> Callable[[int, Any], None]:
        def record(client_id: int, value: Any) -> None:
            with self._changed:
                self.calls.append((name, client_id, value))
                self._changed.notify_all()

        return record

    def connect(
        self,
        origin: str | None = None,
        path: str = "/",
        subprotocol: str | None = VERSION,
        sock: socket.socket | None = None,
    ) -> ClientConnection:
        return connect(
            f"ws://127.0.0.1:{self.port}{path}",
            origin=origin,  # type: ignore[arg-type]
            subprotocols=[subprotocol] if subprotocol else None,  # type: ignore[list-item]
            open_timeout=10,
            max_size=None,
            sock=sock,
        )

    def wait(self, condition: Callable[[], bool], what: str, timeout_s: float = 10.0) -> None:
        deadline = time.monotonic() + timeout_s
        with self._changed:
            while not condition():
                left = deadline - time.monotonic()
                assert left > 0, f"timed out waiting for {what}"
                self._changed.wait(min(left, 0.05))

    def sentinel(self) -> str:
        """Add a scene node and flush: a marker a reader waits for."""
        self._sentinels += 1
        name = f"/sentinel_{self._sentinels}"
        self.server.scene.add_frame(name, show_axes=False)
        self.server.flush()
        return name

    def stop(self) -> None:
        adapter.stop(self.server, timeout_s=30.0)


def read_until(ws: ClientConnection, name: str) -> list[dict[str, Any]]:
    """Every message up to and including the scene node ``name``'s creation."""
    seen: list[dict[str, Any]] = []
    deadline = time.monotonic() + 10
    while time.monotonic() < deadline:
        for message in messages_in(ws.recv(timeout=10)):
            seen.append(message)
            if message.get("name") == name and message["type"] == "FrameMessage":
                return seen
    raise AssertionError(f"{name} never arrived")


@pytest.fixture
def served() -> Iterator[Callable[..., Served]]:
    made: list[Served] = []

    def make(policy: DoorPolicy | None = None, lighting: str = "studio") -> Served:
        made.append(Served(policy, lighting))
        return made[-1]

    yield make
    for s in made:
        s.stop()


def refused_status(attempt: Callable[[], Any]) -> int:
    with pytest.raises(InvalidStatus) as refused:
        attempt()
    return refused.value.response.status_code


# 1. origins and the token


OWN_ORIGINS = {
    "127.0.0.1": "http://127.0.0.1:{port}",
    "localhost": "http://localhost:{port}",
    "ipv6-loopback": "http://[::1]:{port}",
    "upper-case": "HTTP://LocalHost:{port}",
    "no-origin": None,
}
FOREIGN_ORIGINS = {
    "other-site": "http://evil.example",
    "other-port": "http://127.0.0.1:{other}",
    "https": "https://localhost:{port}",
    "null": "null",
    "look-alike": "http://localhost.evil.example:{port}",
    "with-user": "http://evil@localhost:{port}",
}


@pytest.mark.parametrize("origin", OWN_ORIGINS.values(), ids=OWN_ORIGINS.keys())
def test_own_origins_and_loopback_spellings_are_let_on(
    served: Callable[..., Served], origin: str | None
) -> None:
    s = served()
    with s.connect(origin and origin.format(port=s.port)) as ws:
        assert messages_in(ws.recv(timeout=10))  # viser's replay of the scene
    assert not s.door.refused


@pytest.mark.parametrize("origin", FOREIGN_ORIGINS.values(), ids=FOREIGN_ORIGINS.keys())
def test_a_foreign_origin_gets_403(served: Callable[..., Served], origin: str) -> None:
    s = served()
    spelled = origin.format(port=s.port, other=s.port + 1)
    assert refused_status(lambda: s.connect(spelled)) == 403
    assert s.door.refused == {"origin": 1}


def test_a_foreign_origin_is_logged_once_a_minute_by_origin(
    served: Callable[..., Served], caplog: pytest.LogCaptureFixture
) -> None:
    s = served()
    with caplog.at_level(logging.WARNING, logger="c2rviz.view"):
        for origin in ("http://evil.example", "http://evil.example", "http://other.example"):
            assert refused_status(lambda origin=origin: s.connect(origin)) == 403
    lines = [r.getMessage() for r in caplog.records if r.name == "c2rviz.view"]
    assert len(lines) == 2
    assert "'http://evil.example'" in lines[0] and f"http://localhost:{s.port}" in lines[0]
    assert "'http://other.example'" in lines[1]
    assert s.door.refused == {"origin": 3}


def test_extra_origins_for_a_reverse_proxy(served: Callable[..., Served]) -> None:
    s = served(DoorPolicy(extra_origins=("https://Robot.Example.org",)))
    for origin in ("https://robot.example.org", "https://robot.example.org:443"):
        with s.connect(origin) as ws:
            ws.recv(timeout=10)
    assert refused_status(lambda: s.connect("http://robot.example.org")) == 403


@pytest.mark.parametrize(
    "policy",
    [
        {"extra_origins": ("robot.example.org",)},
        {"extra_origins": ("https://robot.example.org/path",)},
        {"max_clients": 0},
        {"max_frame_bytes": 0},
        {"token": "two words\n"},
    ],
    ids=["no-scheme", "a-path", "no-clients", "no-bytes", "control-characters"],
)
def test_a_policy_that_cannot_work_is_refused(policy: dict[str, Any]) -> None:
    with pytest.raises(DoorPolicyError, match="viewer"):
        DoorPolicy(**policy)


def test_normalize_origin() -> None:
    assert normalize_origin("http://LOCALHOST") == "http://localhost:80"
    assert normalize_origin("https://[::1]") == "https://[::1]:443"
    assert normalize_origin("http://127.0.0.1:99999") is None
    assert normalize_origin("file://") is None


def test_the_token_is_required_when_set(served: Callable[..., Served]) -> None:
    s = served(DoorPolicy(token="s3cret"))
    assert refused_status(lambda: s.connect()) == 403
    assert refused_status(lambda: s.connect(path="/?token=wrong")) == 403
    assert refused_status(lambda: s.connect(path="/?token=")) == 403
    with s.connect(f"http://localhost:{s.port}", path="/?token=s3cret") as ws:
        ws.recv(timeout=10)
    page = f"http://127.0.0.1:{s.port}"
    for spelling in ("/", "/index.html", "/%69ndex.html", "/./index.html", "//"):
        with pytest.raises(urllib.error.HTTPError) as no_token:
            urllib.request.urlopen(page + spelling, timeout=10)
        assert no_token.value.code == 403, spelling
        no_token.value.close()
    with urllib.request.urlopen(page + "/?token=s3cret", timeout=10) as ok:
        assert b"<html" in ok.read().lower()
    assert s.door.refused == {"token": 8}


def test_the_page_url_carries_the_token_to_the_websocket(served: Callable[..., Served]) -> None:
    s = served(DoorPolicy(token="s3cret"))
    base = f"http://127.0.0.1:{s.port}"
    url = s.door.policy.page_url(base)
    query = parse_qs(urlsplit(url).query)
    assert query["token"] == ["s3cret"]
    (socket_url,) = query["websocket"]
    assert socket_url == f"ws://127.0.0.1:{s.port}/?token=s3cret"
    with s.connect(path=socket_url.split(str(s.port), 1)[1]) as ws:
        ws.recv(timeout=10)
    assert DoorPolicy().page_url(base) == base  # no token: the plain URL


# 2. what a page may say


BAD_IDS = list(bad_messages("slider-uuid", "checkbox-uuid"))


@pytest.mark.parametrize("bad", BAD_IDS)
def test_a_bad_message_changes_nothing_and_reaches_no_other_tab(
    served: Callable[..., Served], bad: str
) -> None:
    s = served()
    frame = bad_messages(s.slider._impl.uuid, s.checkbox._impl.uuid)[bad]
    with s.connect() as page, s.connect() as other:
        read_until(other, s.sentinel())
        page.send(frame)
        page.send(gui_update(s.checkbox._impl.uuid, {"value": True}))  # behind the bad one
        s.wait(lambda: len(s.calls) == 1, "the checkbox value")
        seen = read_until(other, s.sentinel())
        assert not [m for m in seen if m["type"] in ("GuiUpdateMessage", "SetPositionMessage")]
        assert s.calls == [("checkbox", 0, True)]  # viser's client id of the first tab
    assert s.slider.value == 1.5 and s.checkbox.value is False
    assert not s.slider._impl.removed and s.slider._impl.update_cb
    np.testing.assert_allclose(s.frame.position, [0.1, 0.2, 0.3])
    assert s.own_callbacks == []
    assert s.server._share_tunnel is None
    assert sum(s.door.refused.values()) == 1


def test_share_links_and_uploads_are_refused_by_name(
    served: Callable[..., Served], caplog: pytest.LogCaptureFixture
) -> None:
    s = served()
    frames = bad_messages(s.slider._impl.uuid, s.checkbox._impl.uuid)
    with caplog.at_level(logging.WARNING, logger="c2rviz.view"), s.connect() as page:
        for name in ("share-request", "share-disconnect", "upload-start", "upload-part"):
            page.send(frames[name])
        page.send(gui_update(s.button._impl.uuid, {"value": True}))
        s.wait(lambda: len(s.calls) == 1, "the button")
    assert s.door.refused == {"share": 2, "upload": 2}
    assert [r.getMessage() for r in caplog.records] == [
        "dropped a share-link request (the public tunnel is disabled) from a viewer page",
        "dropped a file upload (the viewer takes none) from a viewer page",
    ]


def test_good_values_go_to_the_callback_only(served: Callable[..., Served]) -> None:
    s = served()
    with s.connect() as page, s.connect() as other:
        read_until(other, s.sentinel())
        page.send(gui_update(s.slider._impl.uuid, {"value": 3}))
        page.send(gui_update(s.slider._impl.uuid, {"value": -2.5}))
        page.send(gui_update(s.checkbox._impl.uuid, {"value": True}))
        page.send(gui_update(s.button._impl.uuid, {"value": True}))
        s.wait(lambda: len(s.calls) == 4, "four values")
        assert not [m for m in read_until(other, s.sentinel()) if m["type"] == "GuiUpdateMessage"]
    assert s.calls == [
        ("slider", 0, 3.0),
        ("slider", 0, -2.5),
        ("checkbox", 0, True),
        ("button", 0, True),
    ]
    assert type(s.calls[0][2]) is float
    assert s.slider.value == 1.5 and s.own_callbacks == []  # the caller sets the true value
    assert not s.door.refused


def test_a_frame_over_the_limit_is_refused_by_size(served: Callable[..., Served]) -> None:
    s = served()
    huge = b"\xdd" + (8_000_000).to_bytes(4, "big") + b"\x90" * 8_000_000  # 7.6 MiB of []
    with s.connect() as page, s.connect() as other:
        read_until(other, s.sentinel())
        with pytest.raises(ConnectionClosed) as closed:
            page.send(huge)
            while True:
                page.recv(timeout=10)
        rcvd = closed.value.rcvd
        assert rcvd is None or rcvd.code == 1009  # 1009: message too big
        s.wait(lambda: s.door.refused["oversize"] == 1, "the refusal")
        assert not [m for m in read_until(other, s.sentinel()) if m["type"] == "GuiUpdateMessage"]
    assert s.slider.value == 1.5 and s.calls == []


# 3. and 4. bounded costs, quiet logs


def test_at_most_max_clients_tabs(served: Callable[..., Served]) -> None:
    s = served(DoorPolicy(max_clients=2))
    first, second = s.connect(), s.connect()
    for ws in (first, second):
        ws.recv(timeout=10)
    with s.connect() as third, pytest.raises(ConnectionClosed) as closed:
        third.recv(timeout=10)
    assert closed.value.rcvd is not None and closed.value.rcvd.code == 1013
    assert "full" in closed.value.rcvd.reason
    first.close()
    s.wait(lambda: len(s.door.clients) == 1, "the first tab to leave")
    with s.connect() as fourth:
        fourth.recv(timeout=10)
    second.close()
    assert s.door.refused == {"full": 1}


@pytest.mark.parametrize("subprotocol", ["viser-v0.0.1", None], ids=["old-page", "no-version"])
def test_a_wrong_version_is_closed_quietly(
    served: Callable[..., Served],
    subprotocol: str | None,
    capsys: pytest.CaptureFixture[str],
    caplog: pytest.LogCaptureFixture,
) -> None:
    s = served()
    capsys.readouterr()
    with caplog.at_level(logging.WARNING):
        for _ in range(3):
            with s.connect(subprotocol=subprotocol) as ws, pytest.raises(ConnectionClosed) as c:
                ws.recv(timeout=10)
            assert c.value.rcvd is not None and c.value.rcvd.code == 1002
            assert "Version mismatch" in c.value.rcvd.reason
    assert capsys.readouterr().out == ""
    assert len([r for r in caplog.records if r.name == "c2rviz.view"]) == 1
    assert s.door.refused == {"version": 3}


def test_malformed_frames_log_one_line_and_no_traceback(
    served: Callable[..., Served], caplog: pytest.LogCaptureFixture
) -> None:
    s = served()
    with (
        caplog.at_level(logging.DEBUG, logger="websockets"),
        caplog.at_level(logging.WARNING, logger="c2rviz.view"),
        s.connect() as page,
    ):
        for i in range(50):
            page.send(bytes([0xC1, i]))
            page.send(f"text {i}")
        page.send(gui_update(s.button._impl.uuid, {"value": True}))
        s.wait(lambda: len(s.calls) == 1, "the button")
    warnings = [r for r in caplog.records if r.levelno >= logging.WARNING]
    assert [r.getMessage() for r in warnings] == [
        "dropped a frame that is not a viser message from a viewer page"
    ]
    assert not [r for r in caplog.records if r.exc_info]
    assert s.door.refused == {"frame": 100}


def test_rate_limited_log_holds_back_and_counts() -> None:
    now = [0.0]
    logger = logging.getLogger("test.ratelog")
    records: list[str] = []
    handler = logging.Handler()
    handler.emit = lambda record: records.append(record.getMessage())  # type: ignore[method-assign]
    logger.addHandler(handler)
    try:
        log = RateLimitedLog(logger, interval_s=60.0, clock=lambda: now[0], max_keys=2)
        assert log.warning("a", "one") and not log.warning("a", "two")
        now[0] = 59.0
        assert not log.warning("a", "three") and log.warning("b", "other kind")
        now[0] = 60.0
        assert log.warning("a", "four")
        assert log.warning("c", "a third key: 'b' is forgotten, not 'a'")
    finally:
        logger.removeHandler(handler)
    assert records[:3] == [
        "one",
        "other kind",
        "four (2 more like it held back in the last 60 s)",
    ]


# 5. removal records


def add_and_remove(s: Served, count: int, start: int = 0) -> None:
    for i in range(start, start + count):
        s.server.scene.add_icosphere(f"/markers/m{i}", radius=0.01).remove()


def test_purge_keeps_the_buffer_bounded_over_many_cycles(served: Callable[..., Served]) -> None:
    s = served()
    base = adapter.buffered_messages(s.server)
    add_and_remove(s, 2000)
    assert adapter.buffered_messages(s.server) >= base + 2000  # a record per removal
    assert adapter.purge_removed(s.server) >= 2000
    assert adapter.buffered_messages(s.server) <= base + 2
    with s.connect() as reading:
        stop_reading = threading.Event()

        def read() -> None:
            while not stop_reading.is_set():
                try:
                    reading.recv(timeout=0.1)
                except TimeoutError:
                    continue
                except ConnectionClosed:
                    return

        reader = threading.Thread(target=read)
        reader.start()
        try:
            for cycle in range(10):
                add_and_remove(s, 500, start=10_000 + 500 * cycle)
                s.server.flush()
                # The reader takes the records at its own pace (slow on a busy machine):
                # purge until what it has read is gone, which must happen.
                deadline = time.monotonic() + 60
                while True:
                    adapter.purge_removed(s.server)
                    left = adapter.buffered_messages(s.server)
                    if left <= base + 600:
                        break
                    assert time.monotonic() < deadline, f"{left} messages stay buffered"
                    time.sleep(0.01)
        finally:
            stop_reading.set()
            reader.join()


def test_a_tab_that_never_reads_is_dropped_when_too_far_behind(
    served: Callable[..., Served],
) -> None:
    s = served()
    base = adapter.buffered_messages(s.server)
    stuck = never_reading_tab(s.port)
    try:
        s.wait(lambda: len(s.door.clients) == 1, "the tab")
        rng = np.random.default_rng(0)
        for k in range(4):  # ~12 MB that the tab will never read: viser's send blocks
            points = rng.random((250_000, 3), dtype=np.float32)
            s.server.scene.add_point_cloud(f"/cloud{k}", points, colors=(1.0, 0.0, 0.0))
        s.server.flush()
        add_and_remove(s, 3000)
        assert adapter.purge_removed(s.server, max_lag=1000) < 3000  # held back for the tab
        s.wait(lambda: not s.door.clients, "the stuck tab to be dropped")
        assert s.door.refused["lagging"] >= 1
        adapter.purge_removed(s.server, max_lag=1000)
        assert adapter.buffered_messages(s.server) <= base + 4 * 2 + 2  # clouds, /markers
    finally:
        stuck.close()


# 6. stop


def port_is_free(port: int) -> bool:
    with socket.socket() as probe:
        try:
            probe.bind(("127.0.0.1", port))
        except OSError:
            return False
        return True


def test_stop_returns_with_a_tab_that_never_reads(served: Callable[..., Served]) -> None:
    s = served()
    stuck = never_reading_tab(s.port)
    try:
        s.wait(lambda: len(s.door.clients) == 1, "the tab")
        points = np.random.default_rng(1).random((1_000_000, 3), dtype=np.float32)
        s.server.scene.add_point_cloud("/cloud", points, colors=(1.0, 0.0, 0.0))
        s.server.flush()
        assert adapter.stop(s.server, timeout_s=30.0)
        deadline = time.monotonic() + 30
        while not port_is_free(s.port):
            assert time.monotonic() < deadline, "the port stayed busy"
            time.sleep(0.05)
    finally:
        stuck.close()
    assert adapter.stop(s.server, timeout_s=30.0)  # twice is harmless


def test_stop_frees_the_port_and_prints_nothing(capsys: pytest.CaptureFixture[str]) -> None:
    server = adapter.start("127.0.0.1", 0)
    port = server.get_port()
    assert not port_is_free(port)
    assert adapter.stop(server)
    assert port_is_free(port)
    assert capsys.readouterr().out == ""


@pytest.mark.parametrize("lighting", adapter.LIGHTINGS)
def test_a_tab_is_sent_the_lighting_chosen(served: Callable[..., Served], lighting: str) -> None:
    """studio sends nothing (viser's page then shows its own environment map, lights and
    shadows); plain turns the map and the shadows off and adds a white hemisphere light."""
    s = served(lighting=lighting)
    with s.connect() as ws:
        seen = read_until(ws, s.sentinel())
    lights = [
        (m["type"], m.get("hdri_data", m.get("cast_shadow", m.get("props"))))
        for m in seen
        if m["type"] in ("EnvironmentMapMessage", "EnableLightsMessage", "HemisphereLightMessage")
    ]
    plain = [
        ("EnvironmentMapMessage", None),
        ("EnableLightsMessage", False),
        (
            "HemisphereLightMessage",
            {"sky_color": [255] * 3, "ground_color": [255] * 3, "intensity": 2.0},
        ),
    ]
    assert lights == (plain if lighting == "plain" else [])


def test_an_unknown_lighting_is_refused_before_viser_starts() -> None:
    with pytest.raises(ValueError, match="lighting 'dim' is not one of studio, plain"):
        adapter.start("127.0.0.1", 0, lighting="dim")
    assert LIGHTINGS == adapter.LIGHTINGS  # the flag's choices are the adapter's


# 7. fast sends


def test_queue_pose_sends_what_changed(served: Callable[..., Served]) -> None:
    s = served()
    with s.connect() as ws:
        read_until(ws, s.sentinel())
        adapter.queue_pose(s.frame, np.array([1.0, 2.0, 3.0]), np.array([0.0, 1.0, 0.0, 0.0]))
        seen = read_until(ws, s.sentinel())
        poses = [  # (viser may interleave other scene messages of its own)
            (m["type"], m.get("position", m.get("wxyz")))
            for m in seen
            if m["type"] in ("SetPositionMessage", "SetOrientationMessage")
        ]
        assert poses == [
            ("SetPositionMessage", [1.0, 2.0, 3.0]),
            ("SetOrientationMessage", [0.0, 1.0, 0.0, 0.0]),
        ]
        np.testing.assert_array_equal(s.frame.position, [1.0, 2.0, 3.0])
        np.testing.assert_array_equal(s.frame.wxyz, [0.0, 1.0, 0.0, 0.0])
        adapter.queue_pose(s.frame, np.array([1.0, 2.0, 3.0]), np.array([0.0, 0.0, 1.0, 0.0]))
        seen = read_until(ws, s.sentinel())
        sent = [m["type"] for m in seen if m["type"].startswith(("SetPosition", "SetOrientation"))]
        assert sent == ["SetOrientationMessage"]


def test_set_gui_value_sends_without_calling_back(served: Callable[..., Served]) -> None:
    s = served()
    with s.connect() as page, s.connect() as other:
        read_until(page, s.sentinel())
        read_until(other, s.sentinel())
        assert adapter.set_gui_value(s.slider, 4)
        assert not adapter.set_gui_value(s.slider, 4.0)  # unchanged: nothing sent
        assert s.slider.value == 4.0 and type(s.slider.value) is float
        sentinel = s.sentinel()
        for ws in (page, other):
            updates = [m for m in read_until(ws, sentinel) if m["type"] == "GuiUpdateMessage"]
            assert [u["updates"] for u in updates] == [{"value": 4.0}]
        # The tab that moved the slider is not sent its own value back.
        page.send(gui_update(s.slider._impl.uuid, {"value": 6.0}))
        s.wait(lambda: len(s.calls) == 1, "the slider")
        (_, client_id, value) = s.calls[0]
        assert adapter.set_gui_value(s.slider, value, exclude_client=client_id)
        sentinel = s.sentinel()
        assert not [m for m in read_until(page, sentinel) if m["type"] == "GuiUpdateMessage"]
        updates = [m for m in read_until(other, sentinel) if m["type"] == "GuiUpdateMessage"]
        assert [u["updates"] for u in updates] == [{"value": 6.0}]
    assert s.own_callbacks == []


def test_queue_updates_leaves_viser_s_buffer_as_its_own_push_does(
    served: Callable[..., Served],
) -> None:
    """The batch of pose updates (``PoseBatch``'s one pass) against viser's push one by
    one: the same messages under the same ids, the superseded ones dropped, the same
    indices (what a new tab is replayed, what viser's purge reads)."""
    ours, theirs = served(), served()
    nodes = {s: [s.server.scene.add_frame(f"/batch/{k}") for k in range(3)] for s in (ours, theirs)}
    rounds = [
        [("p", 0, (1.0, 2.0, 3.0)), ("o", 0, (0.0, 1.0, 0.0, 0.0)), ("o", 2, (0.5,) * 4)],
        [("o", 0, (0.0, 0.0, 1.0, 0.0)), ("p", 1, (4.0, 5.0, 6.0)), ("o", 2, (1.0, 0, 0, 0))],
    ]
    make = {"p": viser_internals._Position, "o": viser_internals._Orientation}
    for batch in rounds:
        messages = {
            s: [make[kind](nodes[s][k]._impl.name, value) for kind, k, value in batch]
            for s in (ours, theirs)
        }
        with ours.server.atomic():
            viser_internals.queue_updates(ours.server.scene, messages[ours])
        with theirs.server.atomic():
            for m in messages[theirs]:
                theirs.server.scene._queue_scene_message(m)

    def kept(s: Served) -> tuple[Any, ...]:  # the nodes' (the panels' ids are random)
        buffer = s.server._websock_server._broadcast_buffer
        return (
            buffer.message_counter,
            {
                i: m.as_serializable_dict([])
                for i, m in buffer.message_from_id.items()
                if getattr(m, "name", "").startswith("/batch")
            },
            {k: i for k, i in buffer.id_from_redundancy_key.items() if "/batch" in k},
            {k: v for k, v in buffer.ids_from_entity_state_key.items() if "/batch" in k[1]},
        )

    assert kept(ours) == kept(theirs)
    with ours.connect() as ws:  # and a new tab is told the newest pose of each
        seen = [m for m in read_until(ws, ours.sentinel()) if m.get("name") == "/batch/0"]
        poses = [m for m in seen if m["type"] in ("SetPositionMessage", "SetOrientationMessage")]
        assert [(m["type"], m.get("position", m.get("wxyz"))) for m in poses] == [
            ("SetPositionMessage", [1.0, 2.0, 3.0]),
            ("SetOrientationMessage", [0.0, 0.0, 1.0, 0.0]),
        ]


def test_a_fast_message_that_no_longer_matches_viser_s_fails_loudly(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The fast messages put on the wire what viser would; when a viser upgrade changes
    its message, the check says so (before a tab is sent a message it cannot read)."""
    adapter.check()
    monkeypatch.setattr(
        viser_internals._Orientation,
        "as_serializable_dict",
        lambda self, buffers=None: {"name": self.name, "type": "SetOrientationMessage"},
    )
    with pytest.raises(adapter.ViserInternalsError, match="SetOrientationMessage as c2rviz"):
        adapter.check()


# 8. the version check


def private_attributes_used_by_the_adapter() -> set[str]:
    used: set[str] = set()
    for source in ADAPTER_SOURCES:
        tree = ast.parse(source.read_text())
        used |= {
            node.attr
            for node in ast.walk(tree)
            if isinstance(node, ast.Attribute)
            and node.attr.startswith("_")
            and not node.attr.startswith("__")
        }
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("viser"):
                used |= {a.name for a in node.names if a.name.startswith("_")}
    return used


def test_check_passes_and_every_private_name_used_is_checked(
    served: Callable[..., Served],
) -> None:
    adapter.check()
    listed = {part for where, names in adapter.INTERNALS for part in (*where.split("."), *names)}
    used = private_attributes_used_by_the_adapter()
    assert used >= {"_impl", "_websock_server", "_run_garbage_collector", "_messages"}
    assert used <= listed, f"not in adapter.INTERNALS: {sorted(used - listed)}"
    s = served()
    assert adapter.missing_internals(s.server) == []
    # The handles' private paths, as queue_pose and set_gui_value walk them.
    assert callable(s.frame._impl.api._queue_scene_message)
    assert callable(s.slider._impl.gui_api._websock_interface.queue_message)


def test_a_missing_internal_fails_loudly(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delattr(viser.ViserServer, "_run_garbage_collector")
    with pytest.raises(adapter.ViserInternalsError, match="_run_garbage_collector.*1.1.x"):
        adapter.check()


def test_a_websocket_server_started_another_way_fails_loudly(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setattr(adapter, "_VISER_SERVE_MODULE", "somewhere.else")
    with pytest.raises(adapter.ViserInternalsError, match="serve"):
        adapter.start("127.0.0.1", 0)


# the real page


@pytest.mark.browser
def test_the_real_page_gets_through_with_its_token(
    served: Callable[..., Served], browser: Any
) -> None:
    """viser's own page, opened at the printed URL: it connects, nothing it says is
    dropped, and a click on the button reaches the callback."""
    s = served(DoorPolicy(token="s3cret"), lighting="plain")  # the door, not the look
    page = browser.new_page()
    page.goto(s.door.policy.page_url(f"http://127.0.0.1:{s.port}"))
    # viser counts a tab once its first camera update got through the door.
    s.wait(lambda: bool(s.server.get_clients()), "the page's camera", timeout_s=60)
    page.get_by_text("button", exact=True).click()
    s.wait(lambda: bool(s.calls), "the click", timeout_s=30)
    assert s.calls == [("button", 0, True)]
    assert not s.door.refused
