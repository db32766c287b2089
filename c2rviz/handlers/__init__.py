"""What every verb does: one module of ``@handler`` functions per concern.

Importing this package registers every handler in ``registry.HANDLERS``; the
verbs themselves are declared in ``commands`` and ``lang``.
"""

from . import motion, record, seed

__all__ = ["motion", "record", "seed"]
