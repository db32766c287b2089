"""What every verb does: ``@handler`` functions, one module per ``protocol.verbs`` module,
of the same name and in the same order:

============  ===================================================================
module        verbs
============  ===================================================================
``seed``      the joints, the markers, the questions, ``sleep``, ``bye``, ``quit``
``arm``       the tool, IK and Cartesian moves; the cell's robots; motion
``scene``     ``watch``, ``trail``, ``ghost``, ``record``; the workcell; ``plan``
``parts``     the gripper, parts, goals, the score; cameras
``faults``    faults, ``reset``
============  ===================================================================

The import below is the whole list: importing this package registers every handler in
``registry.HANDLERS`` (the ``session`` package does, so a session can run every verb;
``tests/protocol/test_registry.py`` checks that every verb has exactly one).
"""

from . import arm, faults, parts, scene, seed

__all__ = ["arm", "faults", "parts", "scene", "seed"]
