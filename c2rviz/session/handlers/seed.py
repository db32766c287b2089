"""What the seed's verbs do (``protocol.verbs.seed``): the joints (``rand``, ``home``,
``degrees``/``radians``, ``joints``, ``move``), the markers (``clear``, ``mark``,
``color``/``rgb``, ``marker``), the questions (``where``, ``pose``, ``limits``,
``names``, ``version``, ``help``), and ``sleep``, ``bye``, ``quit``.
"""

from __future__ import annotations

import hashlib
from typing import TYPE_CHECKING

from ... import __version__
from ...errors import BadArguments, JointCountError, JointIndexError
from ...protocol import replies
from ...protocol.registry import Reply, handler, usage
from ...protocol.verbs.seed import (
    Bye,
    Clear,
    Color,
    Help,
    Home,
    Joints,
    Limits,
    Mark,
    MarkerShape,
    Move,
    Names,
    Pose,
    Quit,
    Rand,
    Sleep,
    Units,
    Version,
    Where,
)
from ..guarded import guarded_rand

if TYPE_CHECKING:
    from ..session import Session


@handler(Rand)
def rand(session: Session, command: Rand) -> Reply:
    if session.guard:  # a configuration that collides with nothing, drawn off the loop
        return guarded_rand(session)
    return session.go(session.robot.random(session.services.rng))


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
    within = table.within(values)
    return session.go(table.to_si(values) if within else session.to_si(range(n), values))


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
    pose = None if command.pose is None else session.pose_se3(command.pose)
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
    q = session.world.faults.sensed(session.state.name, session.now())  # encoder noise, if on
    return replies.ok(replies.numbers(session.from_si(q)))


@handler(Pose)
def pose(session: Session, command: Pose) -> str:
    placement = session.robot.ee_pose(session.now()) * session.state.tool
    return replies.ok(session.pose_text(placement))


@handler(Limits)
def limits(session: Session, command: Limits) -> str:
    table = session.table
    ranges = [
        f"{replies.limit(lo)}..{replies.limit(hi)} {unit}"
        for lo, hi, unit in zip(table.lower, table.upper, table.unit)
    ]
    if command.all:
        motion = session.travel.motion.limits
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
    if command.verb is None:
        return replies.help_reply()
    return replies.ok(command.reply_text())


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
