"""What each verb of the seed's language does: one ``@handler`` per command class.

A handler gets the ``Session`` (the source's robot, units and style) and the
parsed command; it checks everything first, then changes the world, and
returns the reply — a string now, or an awaitable for a reply that waits.
"""

from __future__ import annotations

import hashlib
from collections.abc import Sequence
from operator import le, mul
from typing import TYPE_CHECKING

import numpy as np
import pinocchio as pin

from ... import __version__
from ...errors import BadArguments, JointCountError, JointIndexError
from ...protocol import replies
from ...protocol.registry import Reply, handler, usage
from ...protocol.verbs.connection import Bye, Quit, Sleep
from ...protocol.verbs.joints import Home, Joints, Move, Rand, Units
from ...protocol.verbs.markers import Clear, Color, Mark, MarkerShape
from ...protocol.verbs.queries import Help, Limits, Names, Pose, Version, Where

if TYPE_CHECKING:
    from ..session import Session

__all__: list[str] = []


@handler(Rand)
def rand(session: Session, command: Rand) -> Reply:
    rng = session.world.rng
    if session.guard:  # a configuration that collides with nothing
        return session.go(session.world.collision_model(session.state.name).random_free(rng))
    return session.go(session.robot.random(rng))


@handler(Home)
def home(session: Session, command: Home) -> Reply:
    return session.go(session.robot.home)


@handler(Units)
def units(session: Session, command: Units) -> str:
    session.set_degrees(command.degrees)
    return replies.OK


@handler(Joints)
def joints(session: Session, command: Joints) -> Reply:
    values = command.values
    n = session.n
    if len(values) != n:
        raise JointCountError(n, len(values))
    table = session.table
    # The hot path (a stream of `joints` lines): all within limits, checked in C.
    q: Sequence[float]
    if all(map(le, table.lower, values)) and all(map(le, values, table.upper)):
        q = values if table.identity else tuple(map(mul, values, table.scale))
    else:
        q = session.to_si(range(n), values)
    return session.go(q)


@handler(Move)
def move(session: Session, command: Move) -> Reply:
    n = session.n
    for index in command.indices:
        if index >= n:
            raise JointIndexError(index, session.state.name, n)
    q = list(session.state.target)
    for index, value in zip(command.indices, session.to_si(command.indices, command.values)):
        q[index] = value
    return session.go(q)


@handler(Clear)
def clear(session: Session, command: Clear) -> Reply:
    session.world.clear_markers(session.state.name)
    return session.go(session.robot.home)


@handler(Mark)
def mark(session: Session, command: Mark) -> str:
    pose = None
    if command.pose is not None:
        x, y, z, roll, pitch, yaw = command.pose
        angle = session.angle_scale
        rotation = pin.rpy.rpyToMatrix(roll * angle, pitch * angle, yaw * angle)
        pose = pin.SE3(rotation, np.array([x, y, z]))
    session.world.add_marker(
        pose, session.rgb, session.shape, session.state.name, in_world=command.in_world
    )
    return replies.OK


@handler(Color)
def color(session: Session, command: Color) -> str:
    session.rgb = command.rgb
    return replies.OK


@handler(MarkerShape)
def marker_shape(session: Session, command: MarkerShape) -> str:
    session.shape = command.shape
    return replies.OK


@handler(Where)
def where(session: Session, command: Where) -> str:
    return replies.ok(replies.numbers(session.from_si(session.now())))


@handler(Pose)
def pose(session: Session, command: Pose) -> str:
    placement = session.robot.ee_pose(session.now()) * session.state.tool
    rpy = pin.rpy.matrixToRpy(placement.rotation) / session.angle_scale
    return replies.ok(replies.numbers([*placement.translation, *rpy]))


@handler(Limits)
def limits(session: Session, command: Limits) -> str:
    table = session.table
    ranges = [
        f"{replies.limit(lo)}..{replies.limit(hi)} {unit}"
        for lo, hi, unit in zip(table.lower, table.upper, table.unit)
    ]
    if command.all:
        motion = session.state.travel.motion.limits
        ranges = [
            f"{text} v={replies.numbers([v / s])} a={replies.numbers([a / s])} "
            f"j={replies.numbers([j / s])}"
            for text, v, a, j, s in zip(
                ranges, motion.velocity, motion.acceleration, motion.jerk, table.scale
            )
        ]
    return replies.ok(",".join(ranges))


@handler(Names)
def names(session: Session, command: Names) -> str:
    return replies.ok(f"{session.state.name} {','.join(session.robot.joint_names)}")


@handler(Version)
def version(session: Session, command: Version) -> str:
    source = session.robot.source
    digest = hashlib.sha256(source.xml.encode()).hexdigest()[:12]
    name = source.path.name if source.path is not None else "(urdf text)"
    return replies.ok(f"c2rviz {__version__} {name} sha256:{digest}")


@handler(Help)
def help_(session: Session, command: Help) -> str:
    return replies.help_reply()


@handler(Sleep)
def sleep(session: Session, command: Sleep) -> Reply:
    longest = session.limits.max_sleep_s
    if command.seconds > longest:
        raise BadArguments(
            "sleep", f"{command.seconds:g} s is over the limit of {longest:g} s", usage("sleep")
        )
    return session.after(command.seconds, replies.OK)


@handler(Bye)
def bye(session: Session, command: Bye) -> str:
    session.hangup = "bye"
    return replies.BYE


@handler(Quit)
def quit_(session: Session, command: Quit) -> str:
    session.hangup = "quit"
    return replies.OK
