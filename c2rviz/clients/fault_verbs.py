"""The calls of the clients' fault methods (docs/faults.md), pure: arguments checked
before anything is sent (the methods are ``aio_verbs.AsyncVerbs``'s).

Times are in seconds of the server's clock, noise in the connection's angle unit,
latency in milliseconds.
"""

from __future__ import annotations

from ..protocol.verbs.faults import FAULT_KINDS
from . import arguments as check
from . import records as read
from .calls import Call, fixed, parsed

__all__ = ["FAULTS", "RESET", "clear_faults", "fault", "read_faults"]


def read_faults(reply: str) -> list[str]:
    """``ok none`` -> []; ``ok estop since 1.500; noise 0.01 at 5.000`` -> each item."""
    if not reply.startswith("ok "):
        raise ValueError(reply)
    body = reply[3:]
    return [] if body == "none" else body.split("; ")


def fault(kind: object, args: tuple[object, ...], at: object, after: object) -> Call[None]:
    chosen = check.choice("fault", "kind", kind, tuple(FAULT_KINDS))
    words = ["fault"]
    if at is not None:
        words += ["at", repr(check.number("fault", "at", at))]
    if after is not None:
        words += ["after", repr(check.number("fault", "after", after))]
    words.append(chosen)
    if args:
        if not any(isinstance(a, str) for a in args):
            words.append(",".join(repr(check.number("fault", "args", a)) for a in args))
        else:
            words.extend(str(a) for a in args)
    return Call(parsed("fault", "args", " ".join(words)), read.read_ok)


def clear_faults(kind: object) -> Call[None]:
    chosen = check.choice("clear_faults", "kind", kind, (*FAULT_KINDS, "all"))
    return Call(f"fault clear {chosen}", read.read_ok)


FAULTS = fixed("faults", read_faults)
RESET = fixed("reset", read.read_ok)
