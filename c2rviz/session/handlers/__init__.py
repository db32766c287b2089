"""What every verb does: one module of ``@handler`` functions per family of verbs, each
mirroring its ``protocol.verbs`` module.

Importing this package registers every handler in ``registry.HANDLERS`` (the
``session`` package does, so a session can run every verb).
"""

from . import (
    cameras,
    cartesian,
    cell,
    connection,
    faults,
    gripper,
    joints,
    markers,
    motion,
    observe,
    parts,
    planning,
    queries,
    record,
    workcell,
)

__all__ = [
    "cameras",
    "cartesian",
    "cell",
    "connection",
    "faults",
    "gripper",
    "joints",
    "markers",
    "motion",
    "observe",
    "parts",
    "planning",
    "queries",
    "record",
    "workcell",
]
