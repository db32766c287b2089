"""What the verbs that place things in this connection's scene do: the markers
(``clear``, ``mark``, ``color``/``rgb``, ``marker``; ``protocol.verbs.markers``), the
workcell's objects, collisions now and this connection's guard (``object``,
``objects``, ``collisions``, ``guard``; ``protocol.verbs.workcell``), and the cell's
robots (``robot``, ``robots``; ``protocol.verbs.cell``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ...protocol import replies
from ...protocol.registry import Reply, handler
from ...protocol.verbs.cell import RobotChoice, RobotsList
from ...protocol.verbs.markers import Clear, Color, Mark, MarkerShape
from ...protocol.verbs.workcell import Collisions, Guard, ObjectEdit, Objects

if TYPE_CHECKING:
    from ...collision.model import CollisionModel
    from ..session import Session


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


@handler(ObjectEdit)
def object_edit(session: Session, command: ObjectEdit) -> str:
    name, shape = command.name, command.shape

    def edit(model: CollisionModel) -> None:
        if shape != "remove":
            model.set_object(name, shape, command.size, session.pose_se3(command.pose))
        elif name == "all":
            model.remove_all()
        else:
            model.remove_object(name)

    session.world.edit_objects(session.state.name, edit)
    return replies.OK


@handler(Objects)
def objects(session: Session, command: Objects) -> str:
    names = session.world.collision_model(session.state.name).objects()
    return replies.ok(",".join(names) if names else "none")


@handler(Collisions)
def collisions(session: Session, command: Collisions) -> str:
    return replies.ok(replies.pairs(session.world.contacts.now(session.state.name)))


@handler(Guard)
def guard(session: Session, command: Guard) -> str:
    if command.on is None:
        if not session.guard:
            return replies.ok("off")
        return replies.ok("plan" if session.plan_around else "on")
    if command.on:
        for name in session.world.robots:  # built now, not mid-command (a cell counts all)
            session.world.collision_model(name)
    session.guard = command.on
    session.plan_around = command.plan
    return replies.OK


@handler(RobotChoice)
def robot(session: Session, command: RobotChoice) -> str:
    if command.name is None:
        return replies.ok(session.state.name)
    session.select(command.name)
    return replies.OK


@handler(RobotsList)
def robots(session: Session, command: RobotsList) -> str:
    return replies.ok(
        ",".join(
            name if state.port is None else f"{name}:{state.port}"
            for name, state in session.world.robots.items()
        )
    )
