"""The session layer: one source's robot, units and modes (``session``) and what each verb
does (``handlers``, one module per family of verbs, mirroring ``protocol.verbs``).
Importing the package wires every handler into the registry.
"""

from . import handlers  # noqa: F401  (wires every verb's handler into the registry)
from .services import ServerLimits, Services, SessionDefaults
from .session import Session
from .units import UnitTable

__all__ = ["ServerLimits", "Services", "Session", "SessionDefaults", "UnitTable"]
