"""The clients' methods for faults (docs/faults.md): their calls (pure: arguments checked
before anything is sent) and a part of ``Client`` and of ``AsyncClient`` each.

Times are in seconds of the server's clock, noise in the connection's angle unit,
latency in milliseconds.
"""

from __future__ import annotations

from typing import TypeVar

from ..protocol.verbs.faults import FAULT_KINDS
from . import arguments as check
from . import records as read
from .calls import Call, fixed, parsed, speaks

__all__ = ["AsyncFaultVerbs", "FaultVerbs", "read_faults"]

T = TypeVar("T")


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


class FaultVerbs:
    """Faults on demand (a part of the client)."""

    def call(self, call: Call[T]) -> T:
        raise NotImplementedError  # the client's

    @speaks("fault")
    def fault(
        self, kind: str, *args: float | str, at: float | None = None, after: float | None = None
    ) -> None:
        """Make a fault happen on this robot: now, at the server's clock time ``at`` [s] or
        ``after`` [s] from now. ``fault("estop")``, ``fault("stall", "joint_l")``,
        ``fault("noise", 0.01)`` [rad, or deg], ``fault("latency", 50, 10)`` [ms]."""
        return self.call(fault(kind, args, at, after))

    @speaks("fault")
    def clear_faults(self, kind: str = "all") -> None:
        """End this robot's faults of ``kind`` (``all``: every one, scheduled ones too)."""
        return self.call(clear_faults(kind))

    @speaks("faults")
    def faults(self) -> list[str]:
        """This robot's faults: ``estop since 1.500``, ``noise 0.01 at 5.000`` [s]..."""
        return self.call(FAULTS)

    @speaks("reset")
    def reset(self) -> None:
        """Lift a stop (a protective one, or an emergency stop already cleared)."""
        return self.call(RESET)


class AsyncFaultVerbs:
    """As ``FaultVerbs``, for ``AsyncClient``."""

    async def call(self, call: Call[T]) -> T:
        raise NotImplementedError  # the client's

    @speaks("fault")
    async def fault(
        self, kind: str, *args: float | str, at: float | None = None, after: float | None = None
    ) -> None:
        """As ``FaultVerbs.fault``."""
        return await self.call(fault(kind, args, at, after))

    @speaks("fault")
    async def clear_faults(self, kind: str = "all") -> None:
        """As ``FaultVerbs.clear_faults``."""
        return await self.call(clear_faults(kind))

    @speaks("faults")
    async def faults(self) -> list[str]:
        """As ``FaultVerbs.faults`` [s]."""
        return await self.call(FAULTS)

    @speaks("reset")
    async def reset(self) -> None:
        """As ``FaultVerbs.reset``."""
        return await self.call(RESET)
