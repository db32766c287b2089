"""The browser tests of the page, run again with the page in a process of its own
(``--page-process``, issue 40): the same page, the same guards, the sliders, handles and
buttons through the channel back to the command process. Every browser test that starts
the program is here (the recorded page's are the program's own, unchanged)."""

from __future__ import annotations

import inspect
from collections.abc import Callable
from types import ModuleType
from typing import Any

import pytest
import test_browser
import test_browser_cartesian
import test_browser_instruments
import test_browser_motion
import test_browser_trail
from browser_support import (
    DEADLINE_S,
    LastingProgram,
    changed,
    scene_pixels,
    settle,
    wait_for,
)
from test_browser import other_origin  # noqa: F401 (a fixture a test below asks for)

pytestmark = pytest.mark.browser

SAME: list[tuple[ModuleType, str]] = [
    (test_browser, "test_the_page_follows_commands_and_commands_the_robot"),
    (test_browser, "test_a_page_from_another_origin_cannot_reach_the_viewer"),
    (test_browser, "test_an_object_is_drawn_and_a_link_in_it_turns_red"),
    (test_browser, "test_long_joint_names_stay_on_one_line"),
    (test_browser_cartesian, "test_dragging_the_tool_handle_moves_the_arm"),
    (test_browser_cartesian, "test_clicking_a_marker_and_go_to_puts_the_tool_on_it"),
    (test_browser_trail, "test_a_move_leaves_a_trail_on_the_page"),
    (test_browser_motion, "test_a_move_in_motion_is_drawn_as_it_goes_and_ends_at_the_target"),
    (test_browser_instruments, "test_the_plot_shows_a_joints_command_within_a_frame"),
    (
        test_browser_instruments,
        "test_ghost_off_hides_the_ghost_and_path_and_on_shows_them_until_arrival",
    ),
    (
        test_browser_instruments,
        "test_looking_back_in_the_live_page_shows_the_arm_as_the_csv_has_it",
    ),
]


@pytest.mark.parametrize(
    ("module", "name"), SAME, ids=[f"{m.__name__[5:]}.{n[5:]}" for m, n in SAME]
)
def test_the_same_with_the_page_in_its_own_process(
    module: ModuleType,
    name: str,
    browser: Any,
    c2rviz_process: Callable[..., Any],
    request: pytest.FixtureRequest,
) -> None:
    def in_its_own_process(*args: str, **kwargs: Any) -> Any:
        return c2rviz_process(*args, "--page-process", **kwargs)

    test = getattr(module, name)
    given = {"browser": browser, "c2rviz_process": in_its_own_process}
    shared = {  # the (shared) Motoman, its page on its own
        "motoman": "motoman_page_process",
        "own_motoman": "own_motoman_page_process",
    }
    test(
        **{
            arg: given[arg] if arg in given else request.getfixturevalue(shared.get(arg, arg))
            for arg in inspect.signature(test).parameters
        }
    )


def scene_nodes(page: Any) -> list[str]:
    return page.evaluate("() => Object.keys(window.__viserSceneTree.getState())")  # type: ignore[no-any-return]


def test_parts_goals_cameras_and_the_fault_banner_come_from_the_page_process(
    browser: Any, motoman_page_process: LastingProgram
) -> None:
    """What the in-process page draws of the cell (tests/view/test_view_parts.py,
    test_view_cameras.py, the banner in test_view_instruments.py), drawn by the page
    process from the rows the channel carries, in real Chromium."""
    with motoman_page_process.session() as (_, page, tcp):
        home = settle(page, "page-process-cell-1-home")
        assert tcp.ask("part p1 box 0.1,0.1,0.1 0.6,0.3,0.05,0,0,0") == "ok"
        assert tcp.ask("goal p1 0.6,-0.3,0.05,0,0,0") == "ok"
        assert tcp.ask("camera top 0.6,0,1.2,0,1.5707963267948966,0") == "ok"
        wanted = ("/parts/p1", "/parts/p1/label", "/goals/p1", "/cameras/top/label")
        wait_for(lambda: all(n in scene_nodes(page) for n in wanted), "the part, goal and camera")
        wait_for(lambda: changed(home, scene_pixels(page)) > 200, "the cell drawn")
        settle(page, "page-process-cell-2-drawn")
        assert tcp.ask("fault stall joint_l") == "ok"
        banner = page.locator("code", has_text="stall joint_l")  # the banner's markdown
        banner.first.wait_for(state="visible", timeout=DEADLINE_S * 1000)
        assert page.get_by_text("Faults:").first.is_visible()
        assert tcp.ask("fault clear") == "ok"
        wait_for(lambda: not banner.first.is_visible(), "the banner gone")
        for line in ("part p1 remove", "goal all remove", "camera top remove"):
            assert tcp.ask(line) == "ok", line
        wait_for(lambda: not any(n in scene_nodes(page) for n in wanted), "the cell's things gone")
