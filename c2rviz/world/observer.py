"""What the world hands to views and other observers: its effects, in SI units.

The world calls an ``Observer``'s methods on every accepted change, on the
asyncio thread; they must return at once (a real view stores the latest state
and renders it on its own schedule). An observer overrides what it cares
about; the rest are no-ops. A ``Scene`` is the observer that is a view: it also
has a lifecycle (``start``, ``stop``) and may serve a page (``url``).
``RecordingScene`` is the stand-in for tests, ``NullScene`` the one for running
without a viewer (``--no-viewer``).
"""

from __future__ import annotations

import asyncio
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from .state import MAX_MARKERS, Marker

if TYPE_CHECKING:
    import pinocchio as pin

    from ..collision.workcell import WorkcellObject
    from ..errors import C2rvizError
    from .cameras import Camera
    from .part_rules import Goal
    from .parts import Part


class Observer:
    """Receives the world's effects; every method is called on the asyncio thread."""

    def on_joints(self, robot: str, q: Sequence[float], t: float) -> None:
        """Robot ``robot``'s chain is now at ``q`` [rad or m], at clock time ``t`` [s]."""

    def on_marker(self, robot: str, marker: Marker) -> None:
        """One more marker (past ``MAX_MARKERS``, the oldest is gone)."""

    def on_clear_markers(self, robot: str) -> None:
        """Every marker of ``robot`` is gone."""

    def on_arrived(self, robot: str) -> None:
        """A move of ``robot`` came to rest at its target."""

    def on_stopped(self, robot: str) -> None:
        """A move of ``robot`` came to rest short of its target, after a ``stop``."""

    def on_motion(self, robot: str, t: float) -> None:
        """``robot``'s commanded motion changed at clock time ``t`` [s]: a move started,
        was stopped, or was cut short by a command that put the arm somewhere at once."""

    def on_gripper(self, robot: str, opening: float, t: float) -> None:
        """``robot``'s gripper is now at ``opening`` (0 closed .. 1 open), at time ``t`` [s]."""

    def on_clients(self, count: int) -> None:
        """``count`` TCP clients are connected."""

    def on_command(self, source: str, line: str, accepted: bool) -> None:
        """``source`` sent ``line``; ``accepted`` False if it was refused."""

    def on_commands(self, source: str, lines: Sequence[str]) -> None:
        """``source`` sent ``lines``, all taken at once (a run of ``joints`` lines): as
        ``on_command`` for each, in order (an observer may do it once for them all)."""
        for line in lines:
            self.on_command(source, line, True)

    def on_reply(self, source: str, line: str, reply: str) -> None:
        """``source``'s ``line`` got ``reply`` (its text, errors too), once known: at once,
        or when a reply that waits comes (a move's on arrival); not if it never came."""

    def on_tool(self, robot: str, tool: pin.SE3) -> None:
        """``robot``'s tool point is now ``tool`` (relative to its end-effector link)."""

    def on_objects(self, robot: str, objects: Sequence[WorkcellObject]) -> None:
        """``robot``'s workcell objects are now ``objects`` (placements in its base frame)."""

    def on_collisions(self, robot: str, pairs: Sequence[tuple[str, str]]) -> None:
        """``robot``'s colliding pairs are now ``pairs`` (link or object names)."""

    def on_refused(self, robot: str, source: str, line: str, error: C2rvizError) -> None:
        """``source``'s ``line`` for ``robot`` was refused with ``error`` (at once, or when
        its reply came: a guarded ``movel``); a ``PathCollides`` carries its ``target``."""

    def on_ghost(self, robot: str, shown: bool) -> None:
        """``robot``'s ghost (its target while it travels, its path) is now ``shown`` or not."""

    def on_fault(self, robot: str, text: str) -> None:
        """``robot``'s faults changed: ``text`` says how, as ``watch`` does after ``event``
        (``fault estop``, ``fault stall joint_l``, ``cleared estop``, ``reset``, ``fault
        disconnect``; values in SI, latency in ms)."""

    def on_parts(self, parts: Sequence[Part], t: float) -> None:
        """The parts are now ``parts`` (poses in the world frame), at time ``t`` [s]."""

    def on_part_event(self, robot: str | None, text: str) -> None:
        """A part was ``grasped NAME``, ``released NAME`` (by ``robot``) or is ``resting
        NAME on WHAT`` (robot None)."""

    def on_goals(self, goals: Sequence[Goal]) -> None:
        """The goals are now ``goals`` (poses in the world frame)."""

    def on_cameras(self, cameras: Sequence[Camera]) -> None:
        """The logical cameras are now ``cameras`` (poses in the world frame)."""


def hears(observer: Observer) -> str:
    """What of a command line ``observer`` does something with (its class overrides the
    no-op): ``both`` (the line and its reply), ``commands``, ``replies`` or ``""``."""
    kind = type(observer)
    commands = kind.on_command is not Observer.on_command
    commands = commands or kind.on_commands is not Observer.on_commands
    replies = kind.on_reply is not Observer.on_reply
    return "both" if commands and replies else "commands" if commands else replies * "replies"


class Scene(Observer):
    """An observer that is a view: it starts with the world and stops with the program."""

    url: str | None = None
    """Where a person can look at it, if anywhere."""

    def start(self, loop: asyncio.AbstractEventLoop) -> None:
        """Begin showing the world it was made with; page input goes through ``loop`` (the
        asyncio thread's)."""

    def stop(self) -> None:
        """Stop and free what it holds (ports, threads); later calls do nothing."""


class NullScene(Scene):
    """A scene that draws nothing (``--no-viewer``)."""


@dataclass
class RecordingScene(Scene):
    """A scene that remembers what it was told; no drawing."""

    joints: list[tuple[float, ...]] = field(default_factory=list)
    times: list[float] = field(default_factory=list)
    """The clock time [s] of each entry of ``joints``."""
    markers: list[Marker] = field(default_factory=list)
    clears: int = 0
    client_counts: list[int] = field(default_factory=list)
    commands: list[str] = field(default_factory=list)
    refused: list[str] = field(default_factory=list)
    objects: dict[str, list[str]] = field(default_factory=dict)
    collisions: list[tuple[str, list[tuple[str, str]]]] = field(default_factory=list)
    openings: list[tuple[float, float]] = field(default_factory=list)
    """Each gripper opening published and its clock time [s]."""
    errors: list[tuple[str, str, str]] = field(default_factory=list)
    """(robot, line, message) of each refusal."""
    ghosts: list[tuple[str, bool]] = field(default_factory=list)
    part_times: list[float] = field(default_factory=list)
    """The clock time [s] of each change of the parts."""
    part_events: list[str] = field(default_factory=list)

    def on_joints(self, robot: str, q: Sequence[float], t: float) -> None:
        self.joints.append(tuple(q))
        self.times.append(t)

    def on_gripper(self, robot: str, opening: float, t: float) -> None:
        self.openings.append((opening, t))

    def on_marker(self, robot: str, marker: Marker) -> None:
        self.markers.append(marker)
        del self.markers[:-MAX_MARKERS]

    def on_clear_markers(self, robot: str) -> None:
        self.markers.clear()
        self.clears += 1

    def on_clients(self, count: int) -> None:
        self.client_counts.append(count)

    def on_command(self, source: str, line: str, accepted: bool) -> None:
        (self.commands if accepted else self.refused).append(line)

    def on_objects(self, robot: str, objects: Sequence[WorkcellObject]) -> None:
        self.objects[robot] = [obj.name for obj in objects]

    def on_collisions(self, robot: str, pairs: Sequence[tuple[str, str]]) -> None:
        self.collisions.append((robot, list(pairs)))

    def on_refused(self, robot: str, source: str, line: str, error: C2rvizError) -> None:
        self.errors.append((robot, line, str(error)))

    def on_ghost(self, robot: str, shown: bool) -> None:
        self.ghosts.append((robot, shown))

    def on_parts(self, parts: Sequence[Part], t: float) -> None:
        self.part_times.append(t)

    def on_part_event(self, robot: str | None, text: str) -> None:
        self.part_events.append(text)
