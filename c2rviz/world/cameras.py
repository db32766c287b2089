"""Logical cameras: what a camera at a pose in the world sees of the parts. Pure.

A ``Camera`` stands at a pose in the world frame and looks along its own +x axis, z up,
as Gazebo's logical camera does. Its *frustum* holds the points ``(x, y, z)`` of its
frame with ``0 < x <= range``, ``|atan2(y, x)| <= h_fov / 2`` and
``|atan2(z, x)| <= v_fov / 2`` (the far side is a plane, as Gazebo's). A part is *seen*
when its centre lies in the frustum and is not hidden: the straight segment from the
camera to the part's centre passes through no workcell object (a box, a cylinder or a
sphere; meshes do not hide). Parts do not hide one another. What it reports is each
seen part's name, type and pose in the camera's frame, in the order parts were added.

Noise (``sigma_m``, ``sigma_rad``) adds to each reported pose a normal offset on each of
x, y, z [m] and a rotation by normal angles about x, y, z [rad], from the camera's own
generator (made from the program's seed, so a run repeats). A camera in *blackout*
(``blackout_until`` later than the clock) reports nothing.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

from ..errors import C2rvizError, shown

MAX_CAMERAS = 16
"""Cameras in a world at once."""
DEFAULT_FOV_RAD = (math.radians(60.0), math.radians(45.0))
"""A camera's horizontal and vertical field of view unless told [rad]."""
DEFAULT_RANGE_M = 2.0
"""How far a camera sees unless told [m]."""
MAX_RANGE_M = 100.0
"""The farthest a camera may see [m]."""
DEFAULT_RATE_HZ = 10.0
"""How often ``watch`` reports a camera unless told [1/s]."""
MAX_RATE_HZ = 100.0
"""The most reports a second a camera may make [1/s]."""
_FOV_MAX_RAD = math.pi  # exclusive

Occluder = tuple[str, str, tuple[float, ...], pin.SE3]
"""Something that hides what is behind it: its name, shape, size and world placement."""


class CameraError(C2rvizError):
    """A camera that cannot be added, found or changed."""


class UnknownCamera(CameraError):
    def __init__(self, name: str, names: Sequence[str]) -> None:
        self.name = name
        have = ", ".join(names) if names else "none"
        super().__init__(f"no camera named {shown(name)} (cameras: {have})")


class TooManyCameras(CameraError):
    def __init__(self, limit: int) -> None:
        self.limit = limit
        super().__init__(f"the world already holds {limit} cameras, its limit; remove one first")


@dataclass(eq=False)
class Camera:
    """One logical camera.

    Attributes:
        name: Its name.
        pose: Its pose in the world frame (it looks along its +x axis).
        h_fov_rad: Horizontal field of view, 0 < h_fov < pi [rad].
        v_fov_rad: Vertical field of view, 0 < v_fov < pi [rad].
        range_m: Its far plane, x <= range [m].
        rate_hz: How often ``watch`` reports it (0: never) [1/s].
        sigma_m: Position noise, each axis [m] (0: none).
        sigma_rad: Orientation noise, about each axis [rad] (0: none).
        rng: Where its noise comes from.
        blackout_until: Clock time [s] until which it reports nothing.
    """

    name: str
    pose: pin.SE3
    h_fov_rad: float = DEFAULT_FOV_RAD[0]
    v_fov_rad: float = DEFAULT_FOV_RAD[1]
    range_m: float = DEFAULT_RANGE_M
    rate_hz: float = DEFAULT_RATE_HZ
    sigma_m: float = 0.0
    sigma_rad: float = 0.0
    rng: np.random.Generator = field(default_factory=lambda: np.random.default_rng(0))
    blackout_until: float = -math.inf

    def __post_init__(self) -> None:
        check_view(self.h_fov_rad, self.v_fov_rad, self.range_m)

    def dark(self, now: float) -> bool:
        """The camera is in blackout at clock time ``now`` [s]."""
        return now < self.blackout_until


@dataclass(frozen=True, slots=True)
class Seen:
    """A part a camera sees: its name, type (its name when it has none) and its pose in
    the camera's frame."""

    name: str
    kind: str
    pose: pin.SE3


def check_view(h_fov_rad: float, v_fov_rad: float, range_m: float) -> None:
    """Refuse a field of view outside (0, pi) or a range outside (0, ``MAX_RANGE_M``]."""
    for what, value in (("h_fov", h_fov_rad), ("v_fov", v_fov_rad)):
        if not 0.0 < value < _FOV_MAX_RAD:
            raise CameraError(
                f"{what} = {math.degrees(value):g} deg must be above 0 and below 180 deg"
            )
    if not 0.0 < range_m <= MAX_RANGE_M:
        raise CameraError(f"range = {range_m:g} m must be above 0 and at most {MAX_RANGE_M:g} m")


def in_frustum(camera: Camera, point: np.ndarray) -> bool:
    """True when ``point`` (camera frame [m]) lies inside ``camera``'s frustum."""
    x, y, z = (float(v) for v in point)
    if not 0.0 < x <= camera.range_m:
        return False
    return (
        abs(math.atan2(y, x)) <= camera.h_fov_rad / 2.0
        and abs(math.atan2(z, x)) <= camera.v_fov_rad / 2.0
    )


_EPS = 1e-15


def _slab(
    a: np.ndarray, d: np.ndarray, half: float, low: np.ndarray, high: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Narrow [low, high] to where a + t d lies within -half..half (one axis, every
    segment at once; a segment parallel to the slab and outside it gets low > high)."""
    flat = np.abs(d) < _EPS
    safe = np.where(flat, 1.0, d)
    t0, t1 = (-half - a) / safe, (half - a) / safe
    low = np.where(
        flat, np.where(np.abs(a) <= half, low, np.inf), np.maximum(low, np.minimum(t0, t1))
    )
    high = np.where(flat, high, np.minimum(high, np.maximum(t0, t1)))
    return low, high


def _near(
    a: np.ndarray, d: np.ndarray, radius: float, low: np.ndarray, high: np.ndarray
) -> np.ndarray:
    """Whether a + t d, for some t in [low, high], lies within ``radius`` of the origin
    (``a``: (3,) or (n, 3); ``d``: (n, k), over its k axes)."""
    a = np.broadcast_to(a, d.shape)
    aa = np.einsum("ij,ij->i", a, a)
    ad = np.einsum("ij,ij->i", a, d)
    dd = np.einsum("ij,ij->i", d, d)
    t = np.clip(-ad / np.where(dd < 1e-30, 1.0, dd), np.minimum(low, high), high)  # finite
    return (low <= high) & (aa + 2.0 * ad * t + dd * t * t <= radius * radius)


def segments_hit(shape: str, size: Sequence[float], a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """For each segment from ``a`` (3,) to a row of ``b`` (n, 3), both in the shape's frame
    (centred on it), whether it enters the shape (a box, a cylinder along z, a sphere;
    anything else: never)."""
    d = b - a
    n = len(b)
    low, high = np.zeros(n), np.ones(n)
    if shape == "box":
        for i in range(3):
            low, high = _slab(np.full(n, a[i]), d[:, i], size[i] / 2.0, low, high)
        return low <= high
    if shape == "sphere":
        return _near(a, d, size[0], low, high)
    if shape == "cylinder":
        radius, length = size
        low, high = _slab(np.full(n, a[2]), d[:, 2], length / 2.0, low, high)
        return _near(a[:2], d[:, :2], radius, low, high)
    return np.zeros(n, dtype=bool)  # a mesh does not hide


def hidden_by(
    camera: Camera, targets: np.ndarray, occluders: Sequence[Occluder]
) -> list[str | None]:
    """For each target (rows of ``targets``, world frame [m]), the first occluder the
    segment from the camera to it passes through, or None."""
    found: list[str | None] = [None] * len(targets)
    if not len(targets):
        return found
    origin = camera.pose.translation
    for name, shape, size, placement in occluders:
        rotation, place = placement.rotation, placement.translation
        hits = segments_hit(
            shape, size, rotation.T @ (origin - place), (targets - place) @ rotation
        )
        for i in np.flatnonzero(hits):
            if found[i] is None:
                found[i] = name
    return found


def hidden(camera: Camera, target: np.ndarray, occluders: Sequence[Occluder]) -> str | None:
    """The first occluder the segment from the camera to ``target`` (world frame [m])
    passes through, or None."""
    return hidden_by(camera, np.asarray(target, dtype=float).reshape(1, 3), occluders)[0]


def _noisy(camera: Camera, pose: pin.SE3) -> pin.SE3:
    if camera.sigma_m <= 0.0 and camera.sigma_rad <= 0.0:
        return pose
    offset = camera.rng.normal(0.0, 1.0, 6)
    moved = pose.translation + offset[:3] * camera.sigma_m
    turned = pose.rotation @ pin.exp3(offset[3:] * camera.sigma_rad)
    return pin.SE3(turned, moved)


PartLike = tuple[str, "str | None", pin.SE3]
"""A part as a camera needs it: its name, its type (or None) and its world pose."""


def see(
    camera: Camera,
    parts: Sequence[PartLike],
    occluders: Sequence[Occluder],
    now: float,
    noisy: bool = True,
) -> list[Seen]:
    """What ``camera`` sees at clock time ``now`` [s] (nothing in blackout); ``noisy``
    False: the exact poses, drawing nothing from its generator."""
    if camera.dark(now):
        return []
    into = camera.pose.inverse()
    inside = [
        (name, kind, pose, local)
        for name, kind, pose in parts
        if in_frustum(camera, (local := into * pose).translation)
    ]
    targets = np.array([pose.translation for _, _, pose, _ in inside]).reshape(-1, 3)
    blocked = hidden_by(camera, targets, occluders)
    return [
        Seen(name, kind or name, _noisy(camera, local) if noisy else local)
        for (name, kind, _, local), by in zip(inside, blocked)
        if by is None
    ]


class Cameras:
    """The cameras of a world, in the order they were added; every change is told."""

    def __init__(
        self, changed: Callable[[list[Camera]], None] | None = None, limit: int = MAX_CAMERAS
    ) -> None:
        self.limit = limit
        self._cameras: dict[str, Camera] = {}
        self._changed = changed

    def put(self, camera: Camera) -> None:
        """Add ``camera``, or replace the one of its name (raises ``TooManyCameras``)."""
        if camera.name not in self._cameras and len(self._cameras) >= self.limit:
            raise TooManyCameras(self.limit)
        self._cameras[camera.name] = camera
        self.changed()

    def remove(self, name: str) -> Camera:
        camera = self._cameras.pop(self.get(name).name)
        self.changed()
        return camera

    def get(self, name: str) -> Camera:
        camera = self._cameras.get(name)
        if camera is None:
            raise UnknownCamera(name, list(self._cameras))
        return camera

    def all(self) -> list[Camera]:
        return list(self._cameras.values())

    def blackout(self, name: str, until_s: float) -> None:
        """``name`` reports nothing until clock time ``until_s`` [s] (``-inf``: it reports
        again now; the faults' ``fault blackout CAMERA [S]`` sets this)."""
        self.get(name).blackout_until = until_s
        self.changed()

    def changed(self) -> None:
        """Tell whoever listens that the cameras changed (a pose, a rate, a blackout)."""
        if self._changed is not None:
            self._changed(self.all())

    def __len__(self) -> int:
        return len(self._cameras)

    def __contains__(self, name: object) -> bool:
        return name in self._cameras
