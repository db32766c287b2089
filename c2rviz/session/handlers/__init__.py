"""What every verb does: ``@handler`` functions, grouped by what they act on. Each
``protocol.verbs`` family's handlers live together in one module:

========================  ==============================================================
module                    verb families (``protocol.verbs``)
========================  ==============================================================
``arm``                   ``joints``, ``motion``: the arm moved by its joints
``cartesian``             ``cartesian``: the tool, IK, moves to a tool pose
``scene``                 ``markers``, ``workcell``, ``cell``: what the scene holds, and
                          ``plan``: a path around it
``parts``                 ``parts``: the gripper, parts, goals, the score; ``cameras``
``faults``                ``faults``
``queries``               ``queries``: questions, and ``sleep``, ``bye``, ``quit``
``observe``               ``observe``: watch, trail, ghost, and record
========================  ==============================================================

The import below is the whole list: importing this package registers every handler in
``registry.HANDLERS`` (the ``session`` package does, so a session can run every verb;
``tests/protocol/test_registry.py`` checks that every verb has exactly one).
"""

from . import arm, cartesian, faults, observe, parts, queries, scene

__all__ = [
    "arm",
    "cartesian",
    "faults",
    "observe",
    "parts",
    "queries",
    "scene",
]
