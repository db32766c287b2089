"""Motion on the page, in a real headless Chromium with the whole program behind it.

During a move of a few seconds (`motion on`), the robot's region of the page changes
from one screenshot to the next, and at rest the page shows the same picture as the
target commanded at once. Waits are on signals (test_browser.py).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from browser_support import (
    LastingProgram,
    Tcp,
    changed,
    page_state,
    same_poses,
    scene_pixels,
    settle,
    wait_for,
    wait_for_scene,
)

pytestmark = pytest.mark.browser

TARGET = "90,45,0,-30,0,60,0"  # degrees


def test_a_move_in_motion_is_drawn_as_it_goes_and_ends_at_the_target(
    browser: Any, motoman: LastingProgram
) -> None:
    with motoman.session() as (proc, page, mover):
        asker = Tcp(proc.port)
        home_poses = page_state(page)["poses"]  # type: ignore[index]
        for line in ("degrees", "motion on", "speed 10"):  # a move of several seconds
            assert mover.ask(line) == "ok"
        mover.sock.sendall(f"j {TARGET}\n".encode())  # the reply comes on arrival
        status = asker.ask("status")
        assert status.startswith("ok moving ") and float(status.split()[-1]) > 2.0, status
        # Screenshots while it moves: each one after the page has drawn a new pose.
        shots: list[np.ndarray] = []
        poses = home_poses
        while asker.ask("status").startswith("ok moving") and len(shots) < 3:
            wait_for(
                lambda last=poses: not same_poses((page_state(page) or {}).get("poses", {}), last),
                "the page to draw the arm further on",
            )
            poses = page_state(page)["poses"]  # type: ignore[index]
            shots.append(scene_pixels(page))
        assert len(shots) == 3, "the move ended before three pictures of it were taken"
        assert all(changed(a, b) > 50 for a, b in zip(shots, shots[1:]))
        wait_for(lambda: asker.ask("status") == "ok idle", "the arm to arrive")
        assert mover.file.readline().decode().strip() == "ok"  # the reply on arrival
        # At rest: the page's scene steady after the arrival. Not "unlike the last picture":
        # on a busy machine the page may already have drawn the arm at rest in the third
        # picture, and then no other pose ever comes (a 180 s wait that failed). A pose
        # short of the target would fail below: the target commanded at once never matches.
        end_poses = wait_for_scene(page, "the arm at rest")["poses"]
        moved = settle(page, "motion-1-arrived")
        # The same target commanded at once, from home: the same picture.
        for line in ("motion off", "home"):
            assert mover.ask(line) == "ok"
        wait_for_scene(page, "home", lambda state: same_poses(state["poses"], home_poses))
        assert mover.ask(f"j {TARGET}") == "ok"
        wait_for_scene(page, "the target", lambda state: same_poses(state["poses"], end_poses))
        at_once = settle(page, "motion-2-at-once")
        assert changed(moved, at_once) < 20
        asker.close()
