"""What the connection asks and says of itself: the questions ``where``, ``pose``,
``limits``, ``names``, ``version``, ``help``, and ``sleep``, ``bye``, ``quit`` (all
``protocol.verbs.queries``)."""

from __future__ import annotations

import hashlib
from typing import TYPE_CHECKING

from ... import __version__
from ...errors import BadArguments
from ...protocol import replies
from ...protocol.registry import Reply, handler, usage
from ...protocol.verbs.queries import Bye, Help, Limits, Names, Pose, Quit, Sleep, Version, Where

if TYPE_CHECKING:
    from ..session import Session


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
