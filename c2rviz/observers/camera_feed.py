"""The cameras' reports: on the world's clock, in recordings and as ROS messages.

On the clock, each camera whose rate is above 0 reports
what it sees every ``1 / rate`` seconds (the first at once), while someone listens.

``watch`` streams get them as ``camera NAME T p1:TYPE:x,y,z,roll,pitch,yaw;...`` lines
(``WatchHub``; T counts from the server's start, as ``state`` lines do; ``none`` when
it sees nothing), among the stream's events: a reader too slow to take them loses the
oldest (``event dropped N``). rosbridge publishes them on each camera's topic.

On virtual time a camera's next report is never the only thing that moves the clock:
when nobody holds it and no timer but the cameras' (of any feed) is pending, the camera
waits (parked) until the next command anyone sends (``wake``), so a server whose clients
only listen does not spin.

In recordings and on ROS topics: the lines that place the cameras again (NAME.txt), and
their reports as ROS messages (rosbridge's topics, the bag's). A report is a
``geometry_msgs/msg/PoseArray`` whose header's ``frame_id`` is the camera's frame
``cameras/NAME`` and whose poses are the seen parts' in it, with TF items: the
camera's frame in its parent's and each seen part's frame ``cameras/NAME/PART`` in the
camera's (docs/rosbridge.md says why a PoseArray).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING

import pinocchio as pin

from ..robot.frames import se3_pose
from ..ros.messages import Msg, header
from ..world.cameras import Camera, Seen
from ..world.clock import Timer
from ..world.world import sight
from .bag_topics import xyz_xyzw

if TYPE_CHECKING:
    from ..world.cameras import Seen
    from ..world.world import World


Report = Callable[[str, float, "Sequence[Seen]"], None]
"""``report(camera, t, seen)``: what ``camera`` sees at clock time ``t`` [s]."""


class CameraFeed:
    """The periodic reports of every camera of a world, to one listener."""

    def __init__(self, world: World, report: Report) -> None:
        self.world = world
        self.report = report
        self._timers: dict[str, Timer] = {}
        self._due: dict[str, float] = {}  # when each camera's next report is due [clock s]
        self._period: dict[str, float] = {}
        self._parked: set[str] = set()

    def sync(self, on: bool) -> None:
        """Start, re-rate or stop the reports as the cameras are now (``on``: someone
        listens)."""
        world = self.world
        wanted = {}
        if on:
            wanted = {c.name: 1.0 / c.rate_hz for c in world.cameras.all() if c.rate_hz > 0}
        for name in list(self._period):
            if wanted.get(name) != self._period[name]:
                self._stop(name)
        now = world.clock.now()
        for name, period in wanted.items():
            if name not in self._period:
                self._period[name] = period
                self._arm(name, now)

    def wake(self) -> None:
        """Someone sent a command: parked cameras go on."""
        if self._parked:
            now = self.world.clock.now()
            for name in sorted(self._parked):
                self._arm(name, max(self._due[name], now))
            self._parked.clear()

    def close(self) -> None:
        for name in list(self._period):
            self._stop(name)

    def _stop(self, name: str) -> None:
        timer = self._timers.pop(name, None)
        if timer is not None:
            timer.cancel()
        self._parked.discard(name)
        self._due.pop(name, None)
        self._period.pop(name, None)

    def _arm(self, name: str, when: float) -> None:
        self._due[name] = when
        self._timers[name] = self.world.clock.call_at(when, _tick, self, name)

    def tick(self, name: str) -> None:
        """Camera ``name``'s report is due: make it, and arm the next one."""
        self._timers.pop(name, None)
        world = self.world
        if name not in self._period or name not in world.cameras:
            self._stop(name)
            return
        clock = world.clock
        now = clock.now()
        self.report(name, max(now, self._due[name]), sight(world, name))
        due = self._due[name] + self._period[name]
        if due <= now:  # late (a busy loop on real time): no burst of catch-up reports
            due = now + self._period[name]
        next_timer = getattr(clock, "next_timer", None)
        idle = getattr(clock, "busy_count", 1) == 0
        if next_timer is not None and idle and next_timer(_tick) is None:
            self._due[name] = due
            self._parked.add(name)
            return
        self._arm(name, due)


def _tick(feed: CameraFeed, name: str) -> None:
    """Every feed's timers call this one function, so that the virtual clock can tell the
    cameras' timers (of every feed: watch's, rosbridge's, a bag's) from the rest."""
    feed.tick(name)


POSE_ARRAY = "geometry_msgs/msg/PoseArray"
CAMERA_TOPIC = "/c2rviz/cameras/{name}"
CAMERA_FRAME = "cameras/{name}"

CameraSignature = dict[str, tuple[float, ...]]
"""Each camera's pose, view, rate and noise, by name (what NAME.txt has said)."""


def pose_array(t: float, name: str, seen: Sequence[Seen]) -> Msg:
    """``geometry_msgs/msg/PoseArray`` of what camera ``name`` sees, stamped ``t`` [s]."""
    poses = []
    for one in seen:
        (x, y, z), (qx, qy, qz, qw) = xyz_xyzw(one.pose)
        poses.append(
            {
                "position": {"x": float(x), "y": float(y), "z": float(z)},
                "orientation": {"x": float(qx), "y": float(qy), "z": float(qz), "w": float(qw)},
            }
        )
    return {"header": header(t, CAMERA_FRAME.format(name=name)), "poses": poses}


def camera_items(
    parent: str, to_parent: pin.SE3, camera: Camera, seen: Sequence[Seen]
) -> list[tuple[str, str, Sequence[float], Sequence[float]]]:
    """The camera's frame in ``parent`` and each seen part's in the camera's, as
    ``messages.transforms`` takes them."""
    frame = CAMERA_FRAME.format(name=camera.name)
    items = [(parent, frame, *xyz_xyzw(to_parent * camera.pose))]
    items += [(frame, f"{frame}/{one.name}", *xyz_xyzw(one.pose)) for one in seen]
    return items


def camera_signature(cameras: Sequence[Camera]) -> CameraSignature:
    return {
        c.name: (
            *se3_pose(c.pose),
            c.h_fov_rad,
            c.v_fov_rad,
            c.range_m,
            c.rate_hz,
            c.sigma_m,
            c.sigma_rad,
        )
        for c in cameras
    }


def _exact(values: Sequence[float]) -> str:
    return ",".join(repr(float(v)) for v in values)


def camera_changes(before: CameraSignature, cameras: Sequence[Camera]) -> str:
    """The commands (radians, world frame) from the cameras ``before`` to ``cameras``."""
    now = camera_signature(cameras)
    lines = [f"camera {name} remove\n" for name in before if name not in now]
    for name, values in now.items():
        if before.get(name) == values:
            continue
        lines.append(f"camera {name} {_exact(values[:6])} {_exact(values[6:9])}\n")
        lines.append(f"camera {name} rate {values[9]!r}\n")
        lines.append(f"camera {name} noise {_exact(values[10:12])}\n")
    return "".join(lines)
