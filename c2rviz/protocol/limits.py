"""What one client of each door may cost: one table, the source of every door's limits object.

Each door has one limits object, built from its rows here: the text port's
``session.services.ServerLimits``, CRCL's ``transports.crcl.server.CrclLimits``, rosbridge's
``transports.rosbridge.policy.RosbridgePolicy`` and the page's ``view.door_rules.DoorPolicy``.
A row gives a limit's default and the lowest (and, where the ini and flags set it, the
highest) value allowed; the objects take their defaults with ``default`` and those that
check themselves find the first value below its floor with ``below_floor``. docs/limits.md
shows the same numbers (a test holds them equal). The table stands in ``protocol``
(standard library only) so that every layer reads its numbers here: the CRCL parser's
size cap too, which the clients share.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

DOORS = ("text", "crcl", "rosbridge", "page")
"""The doors, by the names the table uses."""


@dataclass(frozen=True)
class Limit:
    """One limit of one door.

    Attributes:
        door: Which door (one of ``DOORS``).
        name: The field of that door's limits object.
        default: Its value unless the settings say otherwise.
        low: The lowest value allowed (None: not bounded here).
        high: The highest value the ini and flags allow (None: not bounded here).
    """

    door: str
    name: str
    default: float
    low: float | None = None
    high: float | None = None


LIMITS: tuple[Limit, ...] = (
    # the text port (ini and flags: app.config; bounds checked there)
    Limit("text", "max_line", 8192, 64, 1 << 24),
    Limit("text", "max_clients", 64, 1, 100000),
    Limit("text", "max_unread", 1 << 20, 1024, 1 << 30),
    Limit("text", "partial_timeout_s", 10.0, 0.01, 86400),
    Limit("text", "max_sleep_s", 3600.0, 0, 1e6),
    # CRCL (max_unread: the text port's, as the program opens it)
    Limit("crcl", "max_document_bytes", 1 << 20),
    Limit("crcl", "stall_timeout_s", 10.0),
    Limit("crcl", "max_connections", 16),
    Limit("crcl", "max_unread", 1 << 20),
    # rosbridge, in the order its policy checks them
    Limit("rosbridge", "max_frame_bytes", 1 << 20, 1),
    Limit("rosbridge", "max_connections", 32, 1),
    Limit("rosbridge", "max_subscriptions", 64, 1),
    Limit("rosbridge", "max_read_ahead", 2, 1),
    Limit("rosbridge", "max_queue_length", 100, 0),
    # the page's websocket, in the order its policy checks them
    Limit("page", "max_clients", 16, 1, 1024),
    Limit("page", "max_frame_bytes", 64 * 1024, 1),
    Limit("page", "max_queued_frames", 8, 1),
    Limit("page", "log_interval_s", 60.0),
)
"""Every door's limits: one row a limit."""

_BY_NAME = {(row.door, row.name): row for row in LIMITS}


def rows(door: str) -> Iterator[Limit]:
    """The rows of ``door``, in the table's order."""
    return (row for row in LIMITS if row.door == door)


def default(door: str, name: str) -> int:
    """The default of ``door``'s limit ``name`` (an int; see ``default_s`` for seconds)."""
    value = _BY_NAME[(door, name)].default
    assert isinstance(value, int)
    return value


def default_s(door: str, name: str) -> float:
    """The default of ``door``'s limit ``name`` in seconds (a float)."""
    return float(_BY_NAME[(door, name)].default)


def bounds(door: str, name: str) -> tuple[float, float]:
    """The lowest and highest values the ini and flags allow for ``door``'s limit ``name``."""
    row = _BY_NAME[(door, name)]
    assert row.low is not None and row.high is not None
    return row.low, row.high


def below_floor(door: str, limits: object) -> tuple[str, float, float] | None:
    """The first of ``door``'s limits in ``limits`` below its floor, as (field, value,
    floor); None when every one is allowed."""
    for row in rows(door):
        value = getattr(limits, row.name)
        if row.low is not None and value < row.low:
            return row.name, value, row.low
    return None
