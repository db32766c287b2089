"""The pytest plugin (entry point ``pytest11``: loaded by any pytest where c2rviz is installed;
else ``pytest -p c2rviz.testing.plugin``).

Fixtures:

- ``c2rviz_server``: a real server in the test process (``server.TestServer``) on free
  ports, without a page unless asked; a fresh one for every test, so a test that leaves
  the arm moving (or anything else) cannot reach the next.
- ``c2rviz``: a ``c2rviz.Client`` connected to it (radians, the first robot).

Options, from the nearest ``@pytest.mark.c2rviz(...)`` marks (class and module marks too,
the nearest winning) and then a fixture parameter (``indirect=True``, a dict): any flag of
``c2rviz`` by its name (``robot``, ``cell``, ``urdf``, ``clock``, ``motion``, ``speed``,
``guard``, ``hz``, ``max_objects``...), ``ini`` (a cmdinterpreter.ini), ``viewer=True``
(the page, on a free port), ``doors=True`` (the other doors too, on free ports),
``crcl=True`` or ``rosbridge=True`` (that door alone, on a free port:
``c2rviz_server.crcl_port``, ``.rosbridge_port``), ``faults=["after 2 estop", ...]``
(``fault`` lines run on the first robot at the start, docs/faults.md) and
``record=False``. The clock is virtual (``DEFAULT_CLOCK``) unless ``--c2rviz-clock`` (or
the ini option ``c2rviz_clock``) sets every test's, or a mark's ``clock=`` one test's
(``clock="real"`` for a test that needs the wall clock).

Each test's run is recorded (``record NAME`` on its first robot, NAME from the test's
id); when the test fails, NAME.txt, NAME.csv and NAME.html are kept in
``--c2rviz-recordings`` (default ``c2rviz-recordings/`` of the rootdir) and the report
says where; when it passes they are dropped. A test that records itself says
``record=False`` (a robot records one recording at a time).

Under pytest-xdist (``pytest -n auto``) each worker runs its own servers on free ports,
and a recording's name ends in the worker's id (``-gw1``), so two workers running the
same test (``--dist each``, repeats) keep both; the summary of kept recordings is
printed by the controller, from the reports the workers send.
"""

from __future__ import annotations

import re
import shutil
import time
import zlib
from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any

import pytest

if TYPE_CHECKING:  # the server side loads when a test asks for a server, not with pytest
    from ..clients.client import Client
    from .server import TestServer

DEFAULT_CLOCK = "virtual"
"""Every server's clock unless the test, the command line or the ini says otherwise: a test
judges what happened, which virtual time gives at once and the same every run; a test that
needs the wall clock says ``@pytest.mark.c2rviz(clock="real")``."""
_SERVED_WITHIN_S = 60.0
_REPORTS = pytest.StashKey[dict[str, pytest.TestReport]]()
_KEPT = pytest.StashKey[list[Path]]()
_KEPT_PROPERTY = "c2rviz_recording"  # a kept recording's NAME.txt, in the report
_NAME_CHARS = re.compile(r"[^A-Za-z0-9_.-]+")


def pytest_addoption(parser: pytest.Parser) -> None:
    group = parser.getgroup("c2rviz", "c2rviz: test your controller")
    group.addoption(
        "--c2rviz-clock",
        metavar="real|scaled:N|virtual",
        help="the clock of every c2rviz_server (default: the ini's c2rviz_clock, else virtual)",
    )
    group.addoption(
        "--c2rviz-recordings",
        metavar="DIR",
        help="where a failed test's recording is kept (default: c2rviz-recordings/ of the rootdir)",
    )
    parser.addini("c2rviz_clock", "the clock of every c2rviz_server (real, scaled:N, virtual)")
    parser.addini("c2rviz_recordings", "where a failed test's recording is kept")


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line(
        "markers",
        "c2rviz(**options): the c2rviz_server this test gets (robot=, cell=, ini=, clock=, "
        "viewer=, doors=, crcl=, rosbridge=, faults=, record=, and any c2rviz flag by its name)",
    )
    config.stash[_KEPT] = []
    config.pluginmanager.register(_KeptRecordings(config), "c2rviz-kept-recordings")


@pytest.hookimpl(wrapper=True)
def pytest_runtest_call(item: pytest.Item) -> Any:
    """The test's body begins: its servers' clocks run from here (``TestServer.begin``)."""
    from .server import TestServer

    for value in getattr(item, "funcargs", {}).values():
        if isinstance(value, TestServer):
            value.begin()
    return (yield)


@pytest.hookimpl(wrapper=True, tryfirst=True)
def pytest_runtest_makereport(item: pytest.Item, call: pytest.CallInfo[None]) -> Any:
    """Keep each phase's report on the item: the fixture's teardown reads whether it failed."""
    report = yield
    item.stash.setdefault(_REPORTS, {})[report.when] = report
    return report


def pytest_terminal_summary(terminalreporter: Any, config: pytest.Config) -> None:
    kept = config.stash.get(_KEPT, [])
    if kept:
        terminalreporter.section("c2rviz recordings of failed tests")
        for path in kept:
            terminalreporter.write_line(f"{path}  (c2rviz-play {path}; open {path.stem}.html)")


class _KeptRecordings:
    """Notes the recordings tests kept, from their teardown reports: under pytest-xdist a
    worker's reports reach the controller, which prints the summary."""

    def __init__(self, config: pytest.Config) -> None:
        self.config = config

    def pytest_runtest_logreport(self, report: pytest.TestReport) -> None:
        if report.when == "teardown":
            kept = self.config.stash[_KEPT]
            kept += [Path(str(v)) for k, v in report.user_properties if k == _KEPT_PROPERTY]


def recording_name(nodeid: str, worker: str = "") -> str:
    """A recording's name for a test: its id as letters, digits, ``_ . -`` (at most 100),
    then ``-WORKER`` under pytest-xdist (``-gw0``)."""
    name = _NAME_CHARS.sub("_", nodeid.replace("::", "-")).strip("._-") or "test"
    tail = f"-{_NAME_CHARS.sub('_', worker)}" if worker else ""
    room = 100 - len(tail)
    if len(name) > room:
        name = f"{name[: room - 9]}-{zlib.crc32(nodeid.encode()):08x}"
    return name + tail


def _worker(config: pytest.Config) -> str:
    """This pytest-xdist worker's id (``gw0``...), or "" when not under xdist (not from the
    environment: a pytest started by a worker's test inherits that)."""
    workerinput = getattr(config, "workerinput", None)
    return str(workerinput.get("workerid", "")) if isinstance(workerinput, dict) else ""


def _options(request: pytest.FixtureRequest) -> dict[str, Any]:
    clock = request.config.getoption("--c2rviz-clock") or request.config.getini("c2rviz_clock")
    options: dict[str, Any] = {"clock": clock or DEFAULT_CLOCK}
    for mark in reversed(list(request.node.iter_markers("c2rviz"))):  # farthest first
        if mark.args:
            raise pytest.UsageError("@pytest.mark.c2rviz takes options by name only")
        options.update(mark.kwargs)
    param = getattr(request, "param", None)
    if param is not None:
        if not isinstance(param, dict):
            raise pytest.UsageError("a c2rviz_server parameter is a dict of options")
        options.update(param)
    return options


def _kept_folder(config: pytest.Config) -> Path:
    given = config.getoption("--c2rviz-recordings") or config.getini("c2rviz_recordings")
    return Path(given) if given else Path(config.rootpath) / "c2rviz-recordings"


@pytest.fixture
def c2rviz_server(
    request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory
) -> Iterator[TestServer]:
    """A real c2rviz server for this test (see the module docstring for its options)."""
    from .server import TestServer

    options = _options(request)
    record = options.pop("record", True)
    folder = tmp_path_factory.mktemp("c2rviz-recording")
    options.setdefault("record_dir", str(folder))
    server = TestServer(options, held=True).start()
    name = recording_name(request.node.nodeid, _worker(request.config))
    if record:
        reply = server.run(f"record {name} overwrite", server.robot)
        if not reply.startswith("ok"):
            server.stop()
            raise RuntimeError(f"c2rviz_server could not record {name}: {reply}")
    try:
        yield server
    finally:
        reports = request.node.stash.get(_REPORTS, {})
        failed = any(report.failed for report in reports.values())
        if record and not server.quit_requested.is_set():
            server.keep_page(failed)
            server.run("record stop", server.robot)
        server.stop()
        if record and failed:
            _keep(request, Path(options["record_dir"]), name)


def _keep(request: pytest.FixtureRequest, folder: Path, name: str) -> None:
    """Move a failed test's recording where the user looks, and say where."""
    kept = _kept_folder(request.config)
    kept.mkdir(parents=True, exist_ok=True)
    moved = []
    for path in sorted(folder.glob(f"{name}*")):
        target = kept / path.name
        if target.is_dir():
            shutil.rmtree(target)
        shutil.move(str(path), target)
        moved.append(target)
    txt = kept / f"{name}.txt"
    if moved:
        request.node.user_properties.append((_KEPT_PROPERTY, str(txt)))
        request.node.add_report_section(
            "teardown",
            "c2rviz recording",
            f"{txt} (play it: c2rviz-play {txt}; the page: {kept / f'{name}.html'})",
        )


@pytest.fixture
def c2rviz(c2rviz_server: TestServer) -> Iterator[Client]:
    """A ``c2rviz.Client`` connected to this test's server (its first robot, radians)."""
    from ..clients.client import Client

    before = c2rviz_server.text_clients()
    with Client(c2rviz_server.host, c2rviz_server.port, retry_s=0) as client:
        # Served before the test runs: else a test's first idle_clients() could come before
        # the server knows this client, which then holds virtual time inside it.
        deadline = time.monotonic() + _SERVED_WITHIN_S
        while c2rviz_server.text_clients() <= before:
            if time.monotonic() > deadline:
                raise RuntimeError(
                    f"the c2rviz server did not take the client in {_SERVED_WITHIN_S} s"
                )
            time.sleep(0.001)
        c2rviz_server.begin()
        yield client
