"""``--clock virtual``: a program of motion and sleeps (22 s of its clock) runs to its own
schedule exactly, with the same replies and a recording whose stamps equal a real-time
run's. (How far ahead of the wall virtual time runs is a figure, not a test:
``benchmarks/testing_bench.py``.)

Both runs are the program (``python -m c2rviz``) played by ``c2rviz-play``. What a real-time
run adds is the machine's lateness: its loop wakes a little after a timer is due (on a
busy machine, tens of milliseconds), and the recorder writes an arm come to rest at the
end of the frame it rested in. So virtual time is held to the program's own schedule
exactly, and the real run to the virtual one move by move: each move leaves when the
virtual one did plus the real loop's lateness (never earlier), lasts as long within one
frame (and the lateness of the timers that stamp its first and last frames), and ends at
the same pose.
"""

from __future__ import annotations

import csv
import time
from pathlib import Path

import pytest

from c2rviz.clients import player

PROGRAM = """# robot: motoman_sia20d
# Twenty-two seconds of motion and sleeps, recorded. Each move goes with `motion follow`
# and the sleeps keep the cadence (each move ends 2 s or more before the next leaves), so
# neither run waits on the other's round trips.
radians
record {name}
motion follow
speed 60
joints 1,0.5,0,-0.5,0,0.5,0
sleep 4
joints -1,0.3,0.4,-1,0.5,0,1
sleep 5
home
sleep 4
joints 0.5,0.5,0.5,0.5,0.5,0.5,0.5
sleep 3.5
speed 100
joints 0,-0.5,0,0.5,0,-0.5,0
sleep 3.5
speed 60
joints -1,0,0,0,0,0,0
sleep 0.5
stop
sleep 1.5
record stop
"""
HZ = 20.0
FRAME_S = 1.0 / HZ
"""A frame [s]: the recorder writes at most one row per frame, and an arm come to rest at
the frame's end, so a stamp is known to a frame in either run."""


def play(c2rviz_process, tmp_path: Path, clock: str, capsys) -> tuple[float, list[str], Path]:
    """Run the program under ``clock``; the wall time, the player's lines and the CSV."""
    folder = tmp_path / clock
    process = c2rviz_process(
        "--no-viewer", "--clock", clock, "--hz", str(HZ), "--record-dir", str(folder)
    )
    program = tmp_path / f"{clock}.txt"
    program.write_text(PROGRAM.format(name="take"))
    start = time.monotonic()
    status = player.main([str(program), "--port", str(process.port)])
    wall = time.monotonic() - start
    out = capsys.readouterr().out
    assert status == 0, out
    return wall, out.splitlines()[:-1], folder / "take.csv"  # the last line has the time


def moves(path: Path, count: int | None = None) -> list[tuple[float, float, tuple[float, ...]]]:
    """Each move of a recording: when it left, when it arrived [s], and where.

    Frames come every frame while the arm moves and none while it rests, so a move is a
    run of rows without a long gap (the first move begins with the recording's first row):
    a gap over 0.5 s, or with ``count``, the ``count - 1`` longest gaps (the rests, of 2 s
    and more: a busy machine's loop may stall for over 0.5 s mid-move in real time).
    """
    with path.open() as file:
        rows = [(float(row[0]), tuple(map(float, row[1:8]))) for row in list(csv.reader(file))[1:]]
    gaps = [row[0] - before[0] for before, row in zip(rows, rows[1:])]
    if count is None:
        ends = {k for k, gap in enumerate(gaps) if gap > 0.5}
    else:
        ends = set(sorted(range(len(gaps)), key=gaps.__getitem__)[len(gaps) - count + 1 :])
    found = [[rows[0]]]
    for k, row in enumerate(rows[1:]):
        if k in ends:
            found.append([])
        found[-1].append(row)
    return [(move[0][0], move[-1][0], move[-1][1]) for move in found]


SCHEDULE = (0.0, 4.0, 9.0, 13.0, 16.5, 20.0)
"""When each move of ``PROGRAM`` leaves [s from the recording's start]: its sleeps."""
PROGRAM_S = 22.0
"""How long ``PROGRAM`` lasts on its clock from ``record`` on [s]: its sleeps (the last move
is stopped 0.5 s after it leaves at 20 s, then 1.5 s of sleep)."""


def lateness_bound(real_s: float) -> float:
    """Most the real run's loop may have been late for a timer [s]: all the wall time the
    real run took beyond its program's clock time. Every sleep of the real run lasts at
    least its clock time, so a move cannot leave later than that (plus a frame, the stamp
    of its first frame) unless time went wrong; a fixed bound (1 s) failed on a busy
    machine whose loop was that slow."""
    return real_s - PROGRAM_S + FRAME_S


@pytest.mark.timeout(300)
def test_a_program_on_virtual_time_keeps_the_real_runs_stamps(c2rviz_process, tmp_path, capsys):
    virtual_s, virtual_out, virtual_csv = play(c2rviz_process, tmp_path, "virtual", capsys)
    real_s, real_out, real_csv = play(c2rviz_process, tmp_path, "real", capsys)
    # The same replies, in the same order (the recording's own say where and how long).
    assert [line for line in virtual_out if " record " not in line] == [
        line for line in real_out if " record " not in line
    ]
    virtual = moves(virtual_csv)
    real = moves(real_csv, len(virtual))  # as many moves: each must match below
    assert [left for left, _, _ in virtual] == pytest.approx(SCHEDULE, abs=1e-6)
    assert len(real) == len(SCHEDULE)
    simulated = virtual[-1][1]
    assert simulated > 20.5  # the last move leaves at 20 s, is stopped 0.5 s in, and brakes
    assert real_s > simulated
    # Virtual time ran to the program's schedule exactly (above), whatever the wall did; how
    # far ahead of the wall it runs is a figure, benchmarks/testing_bench.py's.
    print(f"virtual time took {virtual_s:.1f} s of the wall, real time {real_s:.1f} s")
    lateness = lateness_bound(real_s)
    for (v_left, v_came, _), (r_left, r_came, _) in zip(virtual, real):
        late = r_left - v_left
        assert 0 <= late < lateness  # real time left when virtual time did, or later
        # As long, within a frame: and the lateness of the two timers that stamp it (the
        # move's first frame, and the one that ends it).
        duration = (r_came - r_left) - (v_came - v_left)
        assert abs(duration) < FRAME_S + lateness
    for (_, _, v_q), (_, _, r_q) in zip(virtual[:-1], real[:-1]):
        assert r_q == pytest.approx(v_q, abs=1e-9)  # to the same pose
    # The last move is stopped 1.5 s in: where it stops depends on when `stop` came.
    assert -0.9 < virtual[-1][2][0] < 0 and -0.9 < real[-1][2][0] < 0
