"""The verbs of the command language, one module per family.

Importing this package registers every verb in ``registry.VERBS``, in the order
``help`` lists them: the order of the imports below (kept out of isort's reach).
"""

# isort: off
from . import joints, markers, queries  # the seed's verbs (queries: then sleep, bye, quit)
from . import (
    cartesian,
    cell,
    motion,
    observe,
    workcell,
)  # observe: then record; workcell: then plan
from . import parts  # grip first, then the part verbs
from . import cameras
from . import faults
# isort: on

__all__ = [
    "cameras",
    "cartesian",
    "cell",
    "faults",
    "joints",
    "markers",
    "motion",
    "observe",
    "parts",
    "queries",
    "workcell",
]
