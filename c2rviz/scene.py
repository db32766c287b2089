"""What the command side hands to a view: the ``Scene`` protocol.

The world calls these methods on every accepted change, on the asyncio thread;
they must return at once (a real view stores the latest state and renders it
on its own schedule). ``RecordingScene`` is the stand-in for tests,
``NullScene`` the one for running without a viewer (``--no-viewer``).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Protocol

__all__ = ["MAX_MARKERS", "Marker", "NullScene", "RecordingScene", "Scene"]

MAX_MARKERS = 1000
"""Markers kept at once; beyond it the oldest goes first, so a flood of ``mark``
costs neither the server's memory nor the page's frame rate."""


@dataclass(frozen=True, slots=True)
class Marker:
    """A marker in the robot's root (world) frame.

    Attributes:
        position: x, y, z [m].
        wxyz: Orientation as a unit quaternion.
        rgb: Colour, each channel 0..1.
        shape: One of ``commands.MARKER_SHAPES``.
    """

    position: tuple[float, float, float]
    wxyz: tuple[float, float, float, float]
    rgb: tuple[float, float, float]
    shape: str


class Scene(Protocol):
    """The view's side of the contract. Every method is called on the asyncio thread."""

    def show_joints(self, q: Sequence[float]) -> None:
        """The chain is now at ``q`` [rad or m]; only the latest value matters."""

    def add_marker(self, marker: Marker) -> None:
        """Show one more marker."""

    def clear_markers(self) -> None:
        """Remove every marker."""

    def set_client_count(self, count: int) -> None:
        """``count`` TCP clients are connected."""

    def note_command(self, line: str) -> None:
        """A client sent ``line`` (for a 'last commands' readout)."""


class NullScene:
    """A scene that draws nothing (``--no-viewer``)."""

    def show_joints(self, q: Sequence[float]) -> None:
        pass

    def add_marker(self, marker: Marker) -> None:
        pass

    def clear_markers(self) -> None:
        pass

    def set_client_count(self, count: int) -> None:
        pass

    def note_command(self, line: str) -> None:
        pass


@dataclass
class RecordingScene:
    """A scene that remembers what it was told; no drawing."""

    joints: list[tuple[float, ...]] = field(default_factory=list)
    markers: list[Marker] = field(default_factory=list)
    clears: int = 0
    client_counts: list[int] = field(default_factory=list)
    commands: list[str] = field(default_factory=list)

    def show_joints(self, q: Sequence[float]) -> None:
        self.joints.append(tuple(q))

    def add_marker(self, marker: Marker) -> None:
        self.markers.append(marker)

    def clear_markers(self) -> None:
        self.markers.clear()
        self.clears += 1

    def set_client_count(self, count: int) -> None:
        self.client_counts.append(count)

    def note_command(self, line: str) -> None:
        self.commands.append(line)
