"""The one token check both browser-reached doors use (``ini.token_ok``)."""

from __future__ import annotations

import pytest

from c2rviz.ini import token_ok
from c2rviz.transports.rosbridge.policy import RosbridgePolicy
from c2rviz.view.door_rules import DoorPolicy


@pytest.mark.parametrize(
    ("token", "path", "ok"),
    [
        (None, "/", True),
        (None, "/?token=anything", True),
        ("abc", "/?token=abc", True),
        ("abc", "/?x=1&token=abc", True),
        ("abc", "/?token=no&token=abc", True),
        ("abc", "/", False),
        ("abc", "/?token=abd", False),
        ("abc", "/?token=", False),
        ("abc", "/?token=abc%20", False),
        ("a b", "/?token=a%20b", True),
        ("", "/?token=", True),
    ],
    ids=[
        "none-needed",
        "none-needed-one-given",
        "given",
        "among-others",
        "second-of-two",
        "missing",
        "wrong",
        "blank",
        "longer",
        "quoted",
        "empty-token",
    ],
)
def test_token_ok(token: str | None, path: str, ok: bool) -> None:
    assert token_ok(token, path) is ok


@pytest.mark.parametrize("path", ["/?token=abc", "/?token=abd", "/"])
def test_both_doors_ask_the_one_check(path: str) -> None:
    expected = token_ok("abc", path)
    assert DoorPolicy(token="abc").token_ok(path) is expected
    assert RosbridgePolicy(token="abc").token_ok(path) is expected
