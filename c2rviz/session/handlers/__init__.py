"""What every verb does: one module of ``@handler`` functions per concern.

Importing this package registers every handler in ``registry.HANDLERS``; the
verbs themselves are declared in ``commands`` and ``lang``.
"""

from . import cartesian, cell, motion, record, seed, workcell

__all__ = ["cartesian", "cell", "motion", "record", "seed", "workcell"]
