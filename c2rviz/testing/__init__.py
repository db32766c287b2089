"""Test your controller: a pytest plugin with a real c2rviz server per test, and assertions.

``plugin`` holds the fixtures (``c2rviz_server``, ``c2rviz``) and the failed-test
recordings; ``server.TestServer`` is the server itself (the program's wiring on a thread
of the test process); ``assertions`` has ``assert_arrives`` and
``assert_no_collision_during``. Importing this package is cheap (pytest loads the plugin
in every run): the server side loads when a test first asks for a server.
"""

from importlib import import_module
from typing import TYPE_CHECKING, Any

from .assertions import (
    assert_arrives,
    assert_goals_met,
    assert_no_collision_during,
    assert_part_at,
)

if TYPE_CHECKING:
    from .server import TestServer

__all__ = [
    "TestServer",
    "assert_arrives",
    "assert_goals_met",
    "assert_no_collision_during",
    "assert_part_at",
]


def __getattr__(name: str) -> Any:
    if name == "TestServer":
        return import_module(".server", __name__).TestServer
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
