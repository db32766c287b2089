"""What a camera of a live world sees now: its parts and occluders gathered from the world.

``cameras.py`` holds the rules (pure); this hands them the world's parts (their world
poses) and every robot's workcell objects (placed in the world) at the clock's time.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

from ..protocol import replies
from ..robot.frames import se3_pose
from .cameras import Occluder, PartLike, Seen, see

if TYPE_CHECKING:
    from .world import World

__all__ = ["occluders", "seen_text", "sight"]


def occluders(world: World) -> list[Occluder]:
    """Every object of every built workcell, placed in the world frame."""
    found: list[Occluder] = []
    for name, state in world.robots.items():
        model = world.contacts.models.get(name)
        if model is None:
            continue
        for obj in model.object_list():
            found.append((obj.name, obj.shape, obj.size, state.base * obj.placement))
    return found


def sight(world: World, name: str, noisy: bool = True) -> list[Seen]:
    """What camera ``name`` sees now (raises ``UnknownCamera``); ``noisy`` False: the exact
    poses, drawing nothing from its generator (the page's look, which must not change
    what the camera reports to clients)."""
    camera = world.cameras.get(name)
    parts: list[PartLike] = [
        (p.name, p.kind or p.obj.shape, p.pose) for p in world.parts.parts.all()
    ]
    return see(camera, parts, occluders(world), world.clock.now(), noisy)


def seen_text(seen: Sequence[Seen], angle_scale: float = 1.0) -> str:
    """``p1:TYPE:x,y,z,roll,pitch,yaw;...`` (metres; angles [rad] / ``angle_scale``: a
    connection's unit), or ``none``."""
    if not seen:
        return "none"
    items = []
    for one in seen:
        x, y, z, roll, pitch, yaw = se3_pose(one.pose)
        angles = [roll / angle_scale, pitch / angle_scale, yaw / angle_scale]
        items.append(f"{one.name}:{one.kind}:{replies.numbers([x, y, z, *angles])}")
    return ";".join(items)
