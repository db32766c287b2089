"""The ini's faults: ``[faults]`` (the first robot's) and ``[faults:ROBOT]``, each entry a
``fault`` command's arguments, started or scheduled when the server starts.

::

    [faults]
    # name = what `fault` takes (radians; `at T` counts from the server's start)
    early_stop = at 5 estop
    shaky = noise 0.002
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from ..errors import C2rvizError, ConfigError
from ..protocol.verbs.faults import FaultVerb
from ..robot.model import Robot
from ..world.faults import Fault, to_fault
from ..world.world import World
from .robot_options import ini_entries

__all__ = ["IniFault", "ini_faults", "start_faults"]

IniFault = tuple[FaultVerb, Fault]
"""A fault of the ini: the command as read, and the fault it starts (SI)."""


def ini_faults(ini: Path, name: str, robot: Robot, first: bool) -> list[IniFault]:
    """The faults the ini gives robot ``name`` (``[faults]`` too when it is the first).

    Raises:
        ConfigError: an entry ``fault`` would refuse, naming it and why.
    """
    found: list[IniFault] = []
    for where, _, text in ini_entries(ini, "faults", name, first):
        try:
            command = FaultVerb.parse("fault", text.split())
            if command.spec is None:
                raise ConfigError("clear is not a fault to start")
            fault = to_fault(name, robot.joint_names, 1.0, command.spec)
        except C2rvizError as exc:
            raise ConfigError(f"{where} = {text!r}: {exc}") from None
        found.append((command, fault))
    return found


def start_faults(world: World, robot: str, commands: Sequence[IniFault]) -> None:
    """Start or schedule the ini's faults of ``robot`` (``at T``: from the server's start;
    a time already past starts it now)."""
    rules = world.faults
    for command, fault in commands:
        if command.at_s is not None:
            rules.schedule(robot, fault, rules.origin + command.at_s)
        elif command.after_s is not None:
            rules.schedule(robot, fault, world.clock.now() + command.after_s)
        else:
            rules.start(robot, fault)
