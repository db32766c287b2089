"""The verbs of the command language, one module per family.

Importing this package registers every verb in ``registry.VERBS``, in the order
``help`` lists them: the order of the imports below (kept out of isort's reach).
"""

# isort: off
from . import seed  # the joints, markers, questions, then sleep, bye, quit
from . import arm  # the tool and Cartesian moves, the cell's robots, motion
from . import scene  # watch, trail, ghost, record; the workcell and plan
from . import parts  # grip first, then the part verbs, then cameras
from . import faults
# isort: on

__all__ = ["arm", "faults", "parts", "scene", "seed"]
