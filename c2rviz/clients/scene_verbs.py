# Written by scripts/unasync_clients.py from c2rviz/clients/aio_scene_verbs.py: do not edit;
# edit aio_scene_verbs.py, then run `python scripts/unasync_clients.py`.
"""``Client``'s methods for the scene: markers, trails, recordings, workcell objects."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import TypeVar

from . import calls, task_calls
from .calls import Call, speaks
from .records import RecordingResult, RecordingStatus, TrailStatus
from .task_calls import CameraInfo, PartState, Score, Seen

T = TypeVar("T")


class SceneVerbs:
    """The verbs of what the cell holds besides the arm: markers, trails, recordings and
    workcell objects (a part of the client; its ``call`` sends)."""

    def call(self, call: Call[T]) -> T:
        raise NotImplementedError  # the client's

    # Markers.

    @speaks("mark")
    def mark(self, pose: Sequence[float] | None = None, *, world: bool = False) -> None:
        """Drop a marker at ``pose`` (x, y, z [m], roll, pitch, yaw [rad, or deg]) in the
        base frame (``world``: the world frame), or at the tool point without one."""
        return self.call(calls.mark(pose, world))

    @speaks("color")
    def color(self, r: float, g: float, b: float) -> None:
        """Colour of this connection's next markers, each channel [0..1]."""
        return self.call(calls.color("color", (r, g, b)))

    @speaks("rgb")
    def rgb(self, r: float, g: float, b: float) -> None:
        """Colour of this connection's next markers, each channel [0..255]."""
        return self.call(calls.color("rgb", (r, g, b)))

    @speaks("marker")
    def marker(self, shape: str) -> None:
        """Shape of this connection's next markers: sphere, cube, arrow or cylinder."""
        return self.call(calls.marker(shape))

    @speaks("clear")
    def clear(self) -> None:
        """Home, and remove every marker."""
        return self.call(calls.CLEAR)

    # Watching, trails, recordings.

    @speaks("unwatch")
    def unwatch(self) -> None:
        """Stop a ``watch`` stream this connection asked with ``send('watch')``."""
        return self.call(calls.UNWATCH)

    @speaks("trail")
    def trail(self, action: str) -> None:
        """The tool's trail: ``on`` (a fresh one), ``off`` or ``clear``."""
        return self.call(calls.trail(action))

    @speaks("trail")
    def trail_status(self) -> TrailStatus:
        """Whether the trail is on, and its points."""
        return self.call(calls.TRAIL_STATUS)

    @speaks("record")
    def record(self, name: str, overwrite: bool = False) -> Path:
        """Record this connection's robot as ``name`` (.txt, .csv, .html); return the
        server's recording folder."""
        return self.call(calls.record(name, overwrite))

    @speaks("record")
    def record_stop(self) -> RecordingResult:
        """End the recording; returns when its files are complete."""
        return self.call(calls.RECORD_STOP)

    @speaks("record")
    def recording(self) -> RecordingStatus | None:
        """The recording running (None: none)."""
        return self.call(calls.RECORDING)

    # The workcell.

    @speaks("object")
    def add_object(
        self, name: str, shape: str, size: float | Sequence[float], pose: Sequence[float]
    ) -> None:
        """Add or replace a workcell object in the base frame: a ``box`` (size sx, sy, sz
        [m]), ``sphere`` (radius [m]) or ``cylinder`` (radius, length [m], along its z);
        ``pose`` x, y, z [m], roll, pitch, yaw [rad, or deg] (a sphere: x, y, z)."""
        return self.call(calls.add_object(name, shape, size, pose))

    @speaks("object")
    def remove_object(self, name: str) -> None:
        """Remove workcell object ``name``."""
        return self.call(calls.remove_object(name))

    @speaks("object")
    def remove_objects(self) -> None:
        """Remove every workcell object."""
        return self.call(calls.REMOVE_OBJECTS)

    @speaks("objects")
    def objects(self) -> list[str]:
        """The workcell objects' names."""
        return self.call(calls.OBJECTS)

    @speaks("collisions")
    def collisions(self) -> list[tuple[str, str]]:
        """The colliding pairs now (link or object names)."""
        return self.call(calls.COLLISIONS)

    @speaks("guard")
    def guard(self, on: bool | None = None) -> bool:
        """Refuse this connection's commands whose target or path collides (``True``);
        return whether the guard is on."""
        return self.call(calls.guard(on))

    # Parts, goals and the score (docs/parts.md).

    @speaks("part")
    def add_part(
        self,
        name: str,
        shape: str,
        size: float | Sequence[float],
        pose: Sequence[float],
        kind: str | None = None,
        color: Sequence[float] | None = None,
    ) -> None:
        """Add part ``name`` a gripper can pick: a ``box`` (size sx, sy, sz [m]), a
        ``cylinder`` (r, length [m]) or a ``sphere`` (r [m]) at ``pose`` (x, y, z [m], roll,
        pitch, yaw [rad, or deg]; a sphere's x, y, z alone) in the base frame; ``kind`` is
        its ``type=``, ``color`` its r, g, b (0..1)."""
        return self.call(task_calls.add_part(name, shape, size, pose, kind, color))

    @speaks("part")
    def part(self, name: str) -> PartState:
        """Where part ``name`` is (x, y, z [m], roll, pitch, yaw [rad, or deg], base frame)
        and what holds it (``free``, ``held``, ``resting on WHAT``)."""
        return self.call(task_calls.part(name))

    @speaks("part")
    def remove_part(self, name: str) -> None:
        """Remove part ``name``."""
        return self.call(task_calls.remove_part(name))

    @speaks("part")
    def remove_parts(self) -> None:
        """Remove every part."""
        return self.call(task_calls.REMOVE_PARTS)

    @speaks("parts")
    def parts(self) -> dict[str, PartState]:
        """Every part by name: its pose (x, y, z [m], roll, pitch, yaw [rad, or deg], base
        frame) and state."""
        return self.call(task_calls.PARTS)

    @speaks("goal")
    def goal(self, target: str, pose: Sequence[float], tol: Sequence[float] | None = None) -> None:
        """Say where part ``target`` (or any part of a type: ``type=T``) should end: ``pose``
        (x, y, z [m], roll, pitch, yaw [rad, or deg], base frame) within ``tol`` (metres,
        angle [rad, or deg]; default 5 mm and 5 degrees)."""
        return self.call(task_calls.goal(target, pose, tol))

    @speaks("goal")
    def remove_goal(self, target: str) -> None:
        """Remove the goal of ``target`` (a part's name or ``type=T``)."""
        return self.call(task_calls.remove_goal(target))

    @speaks("goal")
    def remove_goals(self) -> None:
        """Remove every goal."""
        return self.call(task_calls.REMOVE_GOALS)

    @speaks("score")
    def score(self) -> Score:
        """How many goals are met, and how far off the others are (mm, and degrees or
        radians as the server words it)."""
        return self.call(task_calls.SCORE)

    # Logical cameras (docs/cameras.md).

    @speaks("camera")
    def add_camera(
        self, name: str, pose: Sequence[float], fov: Sequence[float] | None = None
    ) -> None:
        """Place (or move) logical camera ``name`` at ``pose`` (x, y, z [m], roll, pitch, yaw
        [rad, or deg], world frame; it looks along its +x axis) with ``fov`` (h_fov, v_fov
        [rad, or deg], range [m]; default 60, 45 degrees and 2 m)."""
        return self.call(task_calls.add_camera(name, pose, fov))

    @speaks("camera")
    def camera(self, name: str) -> list[Seen]:
        """What camera ``name`` sees now: each part's name, type and pose in the camera's
        frame (x, y, z [m], roll, pitch, yaw [rad, or deg])."""
        return self.call(task_calls.camera(name))

    @speaks("camera")
    def remove_camera(self, name: str) -> None:
        """Remove camera ``name``."""
        return self.call(task_calls.remove_camera(name))

    @speaks("camera")
    def camera_rate(self, name: str, hz: float) -> None:
        """How often [Hz] camera ``name`` reports to ``watch``, rosbridge and bags."""
        return self.call(task_calls.camera_rate(name, hz))

    @speaks("camera")
    def camera_noise(self, name: str, sigma_m: float, sigma_angle: float) -> None:
        """Noise on what camera ``name`` reports: ``sigma_m`` [m] and ``sigma_angle`` [rad,
        or deg], drawn from the server's seed."""
        return self.call(task_calls.camera_noise(name, sigma_m, sigma_angle))

    @speaks("cameras")
    def cameras(self) -> dict[str, CameraInfo]:
        """Every camera by name: its pose (x, y, z [m], roll, pitch, yaw [rad, or deg], world
        frame), fields of view [rad, or deg] and range [m], and rate [Hz]."""
        return self.call(task_calls.CAMERAS)
