"""What the workcell verbs do: objects, collisions now, and this connection's guard."""

from __future__ import annotations

from typing import TYPE_CHECKING

from ...protocol import replies
from ...protocol.registry import handler
from ...protocol.verbs.workcell import Collisions, Guard, ObjectEdit, Objects

if TYPE_CHECKING:
    from ...collision.model import CollisionModel
    from ..session import Session

__all__: list[str] = []


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
