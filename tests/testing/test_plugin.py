"""The pytest plugin as a user's suite meets it: a separate ``pytest`` run (a subprocess) on a
sample test file, loaded with ``-p c2rviz.testing.plugin`` and through its entry point.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from support import ROOT

from c2rviz.testing.server import TestServer

SAMPLE = """
import math

import pytest

from c2rviz import Client, CommandError
from c2rviz.testing import assert_arrives, assert_no_collision_during
from c2rviz.world.virtual_clock import VirtualClock

HOME = (0.0,) * 7


def test_a_client_and_a_server(c2rviz, c2rviz_server):
    assert isinstance(c2rviz, Client)
    assert c2rviz.where() == HOME
    assert c2rviz_server.viewer_url is None  # no page unless asked
    assert c2rviz_server.world.clock.describe() == "virtual"  # the default


def test_leaves_the_arm_moving(c2rviz):
    c2rviz.speed(1)
    c2rviz.motion("follow")
    c2rviz.joints([1, 0, 0, 0, 0, 0, 0])
    assert c2rviz.status().moving  # and the test ends with the arm on its way


def test_the_next_test_starts_at_rest(c2rviz):
    assert c2rviz.status().moving is False and c2rviz.where() == HOME


@pytest.mark.c2rviz(robot="kuka_lwr")
def test_a_marker_chooses_the_robot(c2rviz):
    assert c2rviz.names().robot == "kuka_lwr"


@pytest.mark.parametrize(
    "c2rviz_server", [{"robot": "fanuc_lrmate200id"}, {"robot": "kuka_lwr"}], indirect=True
)
def test_a_parameter_chooses_the_robot(c2rviz, c2rviz_server):
    assert c2rviz.names().robot == c2rviz_server.robot


@pytest.mark.c2rviz(clock="virtual", motion="follow", speed=5)
def test_virtual_time_runs_a_slow_move_at_once(c2rviz, c2rviz_server):
    # Judged on the server's clock: ten minutes and more of it pass in this test (on the
    # real clock that outlasts the suite's time limit); how fast, benchmarks/testing_bench.py.
    assert isinstance(c2rviz_server.world.clock, VirtualClock)
    start = c2rviz_server.now()
    c2rviz.joints([1, 0.5, 0, -0.5, 0, 0.5, 0])
    assert c2rviz.status().seconds_left > 20  # 20 s of the server's clock
    assert_arrives(c2rviz, within=60, at=[1, 0.5, 0, -0.5, 0, 0.5, 0])
    c2rviz.sleep(600)
    assert c2rviz_server.now() - start >= 620


@pytest.mark.c2rviz(motion="follow", speed=50)
def test_assert_arrives_tells_a_late_arrival(c2rviz):
    c2rviz.joints([1, 0, 0, 0, 0, 0, 0])
    with pytest.raises(AssertionError, match="arrives in .* s, not within 0.01 s"):
        assert_arrives(c2rviz, within=0.01)


@pytest.mark.c2rviz(clock="virtual", motion="follow", speed=10)
def test_assert_arrives_tells_a_stop(c2rviz, c2rviz_server):
    c2rviz.joints([1, 0, 0, 0, 0, 0, 0])
    c2rviz_server.run("stop")  # another source stops the arm
    with pytest.raises(AssertionError, match="arrived at .*, not at 1,0,0,0,0,0,0"):
        assert_arrives(c2rviz, within=60, at=[1, 0, 0, 0, 0, 0, 0])


@pytest.mark.c2rviz(clock="virtual", motion="follow", speed=10)
def test_a_second_client_stops_the_first_ones_move(c2rviz, c2rviz_server):
    c2rviz.joints([1, 0, 0, 0, 0, 0, 0])
    c2rviz.sleep(1)  # the arm moves for a second of the clock (none passes between lines)
    with Client(c2rviz_server.host, c2rviz_server.port) as other:
        with c2rviz_server.idle_clients():  # c2rviz waits for nothing meanwhile
            other.stop()
    assert not c2rviz.status().moving and 0 < c2rviz.where()[0] < 1


@pytest.mark.c2rviz(clock="virtual", motion="on")
def test_a_free_move_passes_the_collision_check(c2rviz):
    c2rviz.add_object("table", "box", [1, 1, 0.05], [0.7, 0, 0.3, 0, 0, 0])
    with assert_no_collision_during(c2rviz):
        c2rviz.joints([0.5, 0.3, 0, -0.3, 0, 0.3, 0])


@pytest.mark.c2rviz(clock="virtual", motion="on")
def test_a_move_through_the_table_is_caught(c2rviz):
    c2rviz.add_object("table", "box", [1, 1, 0.05], [0.7, 0, 0.5, 0, 0, 0])
    with pytest.raises(AssertionError, match=r"collision during the block: .*table at t="):
        with assert_no_collision_during(c2rviz):
            c2rviz.joints([0, 1.2, 0, 1.2, 0, 1.0, 0])
    c2rviz.home()
    with assert_no_collision_during(c2rviz, allowed=[("table", "link_l"), ("link_e", "table")]):
        c2rviz.joints([0, 1.2, 0, 1.2, 0, 1.0, 0])


def test_this_one_fails_and_its_run_is_kept(c2rviz):
    c2rviz.joints([0.1, 0.2, 0.3, 0, 0, 0, 0])
    assert c2rviz.where() == HOME, "on purpose"


def test_an_error_reply_is_an_exception(c2rviz):
    with pytest.raises(CommandError, match="outside its limits"):
        c2rviz.joints([0, 9, 0, 0, 0, 0, 0])


@pytest.mark.c2rviz(record=False)
def test_a_test_that_records_itself(c2rviz, tmp_path):
    c2rviz.record("mine")
    assert c2rviz.record_stop().name == "mine"
"""


def run_pytest(
    folder: Path, *args: str, env_extra: dict[str, str] | None = None
) -> subprocess.CompletedProcess[str]:
    """``pytest`` on the sample in ``folder``, as a user runs it (this tree's c2rviz)."""
    env = {**os.environ, "PYTHONPATH": str(ROOT), **(env_extra or {})}
    env.pop("PYTEST_ADDOPTS", None)
    return subprocess.run(
        [sys.executable, "-m", "pytest", "-p", "no:cacheprovider", "-o", "timeout=120", *args],
        cwd=folder,
        capture_output=True,
        text=True,
        timeout=900,
        env=env,
    )


def counts(output: str) -> dict[str, int]:
    last = output.strip().splitlines()[-1]
    return {word: int(n) for n, word in re.findall(r"(\d+) (passed|failed|error)", last)}


@pytest.fixture
def sample(tmp_path: Path) -> Path:
    (tmp_path / "test_controller.py").write_text(textwrap.dedent(SAMPLE))
    (tmp_path / "pytest.ini").write_text("[pytest]\nfilterwarnings = error\n")
    return tmp_path


@pytest.mark.timeout(900)
def test_the_plugin_in_a_users_pytest_run(sample):
    done = run_pytest(sample, "-p", "c2rviz.testing.plugin", "-rA")
    out = done.stdout + done.stderr
    assert counts(out) == {"passed": 14, "failed": 1}, out
    assert "FAILED test_controller.py::test_this_one_fails_and_its_run_is_kept" in out
    assert "AssertionError: on purpose" in out
    kept = sample / "c2rviz-recordings"
    name = "test_controller.py-test_this_one_fails_and_its_run_is_kept"
    files = {path.name for path in kept.iterdir()}
    assert {f"{name}.csv", f"{name}.html", f"{name}.txt"} <= files  # (and a bag, if written)
    assert all(file.startswith(name) for file in files)  # only this test's
    assert f"{kept / name}.txt" in out  # the summary says where
    assert "# robot: motoman_sia20d" in (kept / f"{name}.txt").read_text()
    played = subprocess.run(
        [sys.executable, "-m", "c2rviz.clients.player", str(kept / f"{name}.txt"), "--check"],
        capture_output=True,
        text=True,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
        timeout=120,
    )
    assert played.returncode == 0, played.stderr  # the run plays back


@pytest.fixture(scope="module")
def entry_point_run(tmp_path_factory: pytest.TempPathFactory) -> subprocess.CompletedProcess[str]:
    """One ``pytest --c2rviz-clock virtual`` run, the plugin found only through the
    ``pytest11`` entry point pyproject declares (here a package's metadata on the path says
    the same, as an installed c2rviz's does), of a test of the fixtures and the clock: two
    tests read it (a pytest run costs seconds)."""
    pyproject = (ROOT / "pyproject.toml").read_text()
    section = pyproject.split("[project.entry-points.pytest11]\n")[1].split("\n\n")[0]
    points = dict(re.findall(r'^"?([\w.]+)"? = "([\w.]+)"', section, re.M))
    assert list(points.values()) == ["c2rviz.testing.plugin"]
    site = tmp_path_factory.mktemp("site")
    info = site / "c2rviz_plugin_probe-1.0.dist-info"
    info.mkdir()
    (info / "METADATA").write_text(
        "Metadata-Version: 2.1\nName: c2rviz-plugin-probe\nVersion: 1.0\n"
    )
    lines = "".join(f"{name} = {module}\n" for name, module in points.items())
    (info / "entry_points.txt").write_text(f"[pytest11]\n{lines}")
    folder = tmp_path_factory.mktemp("entry-point")
    (folder / "pytest.ini").write_text("[pytest]\nfilterwarnings = error\n")
    (folder / "test_controller.py").write_text(
        "def test_fixtures(c2rviz, c2rviz_server):\n"
        "    assert c2rviz.where() == (0.0,) * 7\n"
        "    assert c2rviz_server.world.clock.describe() == 'virtual'\n"
    )
    return run_pytest(
        folder,
        "--c2rviz-clock",
        "virtual",
        env_extra={"PYTHONPATH": os.pathsep.join([str(ROOT), str(site)])},
    )


def test_the_entry_point_loads_the_plugin(entry_point_run):
    """pytest finds the plugin (its fixtures, its option) through the entry point alone."""
    done = entry_point_run
    assert counts(done.stdout) == {"passed": 1}, done.stdout + done.stderr


def test_the_clock_option_sets_every_tests_clock(entry_point_run, sample):
    done = entry_point_run  # the clock the option gives is the server's
    assert counts(done.stdout) == {"passed": 1}, done.stdout + done.stderr
    (sample / "test_controller.py").write_text(
        "def test_clock(c2rviz_server):\n"
        "    assert c2rviz_server.world.clock.describe() == 'virtual'\n"
    )
    bad = run_pytest(sample, "-p", "c2rviz.testing.plugin", "--c2rviz-clock", "scaled:0")
    assert counts(bad.stdout) == {"error": 1}
    assert "scaled:0: the factor must be a finite number above 0" in bad.stdout


def test_importing_the_plugin_loads_no_server():
    code = (
        "import sys, c2rviz.testing.plugin\n"
        "print(sorted(m for m in ('pinocchio', 'viser', 'numpy') if m in sys.modules))"
    )
    out = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        check=True,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
    )
    assert out.stdout.strip() == "[]"


@pytest.mark.timeout(900)
def test_the_plugin_under_xdist_keeps_each_workers_recording(sample):
    """Issue 36.5: under pytest-xdist each worker runs its own servers on free ports; with
    every test on both workers (``--dist each``) the failing test fails twice and both
    recordings are kept, each named with its worker, and the controller's summary lists
    them."""
    done = run_pytest(
        sample,
        *("-p", "c2rviz.testing.plugin", "-n", "2", "--dist", "each"),
        *("-k", "fails_and_its_run_is_kept or marker_chooses"),
    )
    out = done.stdout + done.stderr
    assert counts(out) == {"passed": 2, "failed": 2}, out
    kept = sample / "c2rviz-recordings"
    name = "test_controller.py-test_this_one_fails_and_its_run_is_kept"
    for worker in ("gw0", "gw1"):
        txt = kept / f"{name}-{worker}.txt"
        assert {txt.with_suffix(".csv").name, txt.with_suffix(".html").name} <= {
            path.name for path in kept.iterdir()
        }
        assert f"{txt}  (c2rviz-play {txt}" in out  # the controller's summary says where
        assert "# robot: motoman_sia20d" in txt.read_text()


def test_a_recording_name_is_short_and_names_the_worker():
    from c2rviz.testing.plugin import recording_name

    assert recording_name("t.py::test_a[1]") == "t.py-test_a_1"
    assert recording_name("t.py::test_a[1]", "gw3") == "t.py-test_a_1-gw3"
    long = "t.py::test_" + "x" * 200
    named = recording_name(long, "gw12")
    assert len(named) == 100 and named.endswith("-gw12")
    assert named == recording_name(long, "gw12")  # the same in every process (no hash seed)
    assert named != recording_name(long + "y", "gw12")


def test_the_pytest_extra_brings_what_the_docs_say():
    """Issue 39, rough edge 5: docs/testing.md says `pip install -e '.[pytest]'` brings pytest
    and pytest-xdist; pyproject's extra does."""
    import tomllib

    extras = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"][
        "optional-dependencies"
    ]
    names = {re.split(r"[<>=\[ ]", spec)[0] for spec in extras["pytest"]}
    assert {"pytest", "pytest-xdist"} <= names
    page = (ROOT / "docs" / "testing.md").read_text()
    assert (
        "pip install -e '.[pytest]'" in page
        and "installs c2rviz with pytest and pytest-xdist" in page
    )


def test_the_motion_limit_flags_are_options_too():
    """``max_velocity`` and its kin are flags like the others (the program's text for
    them: one number, or one per joint)."""
    server = TestServer(
        {"max_velocity": "0.5", "max_acceleration": "1,2,3,4,5,6,7", "record": False}
    ).start()
    try:
        limits = server.call(lambda: server.world.motion_limits(server.world.default))
        assert list(limits.velocity) == [0.5] * 7
        assert list(limits.acceleration) == [1, 2, 3, 4, 5, 6, 7]
    finally:
        server.stop()
