"""The command language: a line in, a frozen command out, and the reply texts.

Standard library only, no I/O: the clients import this package alone. ``grammar``
holds the pieces every parser uses and ``parse_line``; ``verbs`` one module per
family of verbs (each a frozen dataclass with ``@verb``); ``registry`` the verbs by
name; ``replies`` every reply text; ``framing`` the line framer (bytes in, lines out).
"""

from . import verbs  # noqa: F401  (registers every verb, in help's order)
from .grammar import MARKER_SHAPES, Command, ForeignProtocol, parse_line
from .registry import HANDLERS, LOOKUP, VERBS, Reply, handler, usage, usages, verb

__all__ = [
    "HANDLERS",
    "LOOKUP",
    "MARKER_SHAPES",
    "VERBS",
    "Command",
    "ForeignProtocol",
    "Reply",
    "handler",
    "parse_line",
    "usage",
    "usages",
    "verb",
]
