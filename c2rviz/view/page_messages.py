"""What a viewer page may say: the few viser client messages the door reads, decoded strictly.

Each reader takes one websocket frame (msgpack, viser's wire format) and
returns the message, or raises ``Dropped`` saying what kind of frame it was
and why it is not taken: an unknown field, a number that is not finite, a
quaternion that is not a unit one. Nothing here knows who registered what;
that is the door's.
"""

from __future__ import annotations

import math

import msgspec

__all__ = [
    "CAMERA_FIELDS",
    "CLICK",
    "GRABS",
    "REFUSED",
    "UNIT_TOLERANCE",
    "Click",
    "Dropped",
    "GuiUpdate",
    "HandleGrab",
    "HandleMove",
    "camera_ok",
    "read_click",
    "read_grab",
    "read_input",
    "read_move",
    "read_type",
]

UNIT_TOLERANCE = 1e-3  # how far a handle's quaternion's norm may be from 1
MAX_INSTANCE = 1 << 31  # an instance index of a batched node is below this
GRABS = ("TransformControlsDragStartMessage", "TransformControlsDragEndMessage")
CLICK = "SceneNodeClickMessage"

# Messages a page of this viser version sends but the viewer refuses: (kind, what).
REFUSED = {
    "ShareUrlRequest": ("share", "a share-link request (the public tunnel is disabled)"),
    "ShareUrlDisconnect": ("share", "a share-link request (the public tunnel is disabled)"),
    "FileTransferStartUpload": ("upload", "a file upload (the viewer takes none)"),
    "FileTransferPart": ("upload", "a file upload (the viewer takes none)"),
}


class Dropped(Exception):
    """A frame the door does not take: ``kind`` counts it, ``what`` says it in a log line,
    ``uuid`` names the control it was meant for, when it could be read."""

    def __init__(self, kind: str, what: str, uuid: str | None = None) -> None:
        super().__init__(what)
        self.kind = kind
        self.what = what
        self.uuid = uuid


class _Envelope(msgspec.Struct):
    type: str


class _Value(msgspec.Struct, forbid_unknown_fields=True):
    value: bool | float | str


class GuiUpdate(msgspec.Struct, forbid_unknown_fields=True):
    type: str
    uuid: str
    updates: _Value


class _AnyUpdate(msgspec.Struct):
    uuid: str


class HandleMove(msgspec.Struct, forbid_unknown_fields=True):
    type: str
    name: str
    wxyz: tuple[float, float, float, float]
    position: tuple[float, float, float]
    owner: str = ""


class HandleGrab(msgspec.Struct, forbid_unknown_fields=True):
    type: str
    name: str
    owner: str = ""


class Click(msgspec.Struct, forbid_unknown_fields=True):
    type: str
    name: str
    instance_index: int | None
    ray_origin: tuple[float, float, float]
    ray_direction: tuple[float, float, float]
    screen_pos: tuple[float, float]
    modifier: str | None = None
    owner: str = ""


class _Camera(msgspec.Struct, forbid_unknown_fields=True):
    type: str
    wxyz: tuple[float, float, float, float]
    position: tuple[float, float, float]
    fov: float
    near: float
    far: float
    image_height: int
    image_width: int
    look_at: tuple[float, float, float]
    up_direction: tuple[float, float, float]


CAMERA_FIELDS = tuple(f for f in _Camera.__struct_fields__ if f != "type")
_ENVELOPE = msgspec.msgpack.Decoder(_Envelope)
_GUI_UPDATE = msgspec.msgpack.Decoder(GuiUpdate)
_ANY_UPDATE = msgspec.msgpack.Decoder(_AnyUpdate)
_CAMERA = msgspec.msgpack.Decoder(_Camera)
_HANDLE_MOVE = msgspec.msgpack.Decoder(HandleMove)
_HANDLE_GRAB = msgspec.msgpack.Decoder(HandleGrab)
_CLICK = msgspec.msgpack.Decoder(Click)


def read_type(frame: str | bytes) -> str:
    """The message type of ``frame``."""
    if isinstance(frame, str):
        raise Dropped("frame", "a text frame")
    try:
        return _ENVELOPE.decode(frame).type
    except msgspec.MsgspecError:
        raise Dropped("frame", "a frame that is not a viser message") from None


def read_input(frame: bytes) -> GuiUpdate:
    """A ``{"value": v}`` update of a control (v a number, true/false or a button's label)."""
    try:
        return _GUI_UPDATE.decode(frame)
    except msgspec.MsgspecError:
        try:
            uuid: str | None = _ANY_UPDATE.decode(frame).uuid
        except msgspec.MsgspecError:
            uuid = None
        raise Dropped(
            "input", "an input update other than {'value': a number, true/false or a label}", uuid
        ) from None


def read_move(frame: bytes) -> HandleMove:
    """A transform-controls drag to a finite position and a unit quaternion."""
    try:
        move = _HANDLE_MOVE.decode(frame)
    except msgspec.MsgspecError:
        raise Dropped("handle", "a malformed transform-controls update") from None
    if not all(map(math.isfinite, (*move.wxyz, *move.position))):
        raise Dropped("handle", "a drag to a pose that is not finite")
    if abs(math.sqrt(sum(c * c for c in move.wxyz)) - 1.0) > UNIT_TOLERANCE:
        raise Dropped("handle", "a drag to an orientation that is not a unit quaternion")
    return move


def read_grab(frame: bytes) -> HandleGrab:
    """A transform-controls drag's start or end."""
    try:
        return _HANDLE_GRAB.decode(frame)
    except msgspec.MsgspecError:
        raise Dropped("handle", "a malformed drag start or end") from None


def read_click(frame: bytes) -> Click:
    """A click on a scene node: finite ray and screen point, an instance index or none."""
    try:
        click = _CLICK.decode(frame)
    except msgspec.MsgspecError:
        raise Dropped("click", "a malformed click") from None
    numbers = (*click.ray_origin, *click.ray_direction, *click.screen_pos)
    if not all(map(math.isfinite, numbers)):
        raise Dropped("click", "a click with a ray that is not finite")
    index = click.instance_index
    if index is not None and not 0 <= index < MAX_INSTANCE:
        raise Dropped("click", f"a click on instance {index}")
    return click


def camera_ok(frame: bytes) -> bool:
    """Whether ``frame`` is a well-formed, finite camera update."""
    try:
        c = _CAMERA.decode(frame)
    except msgspec.MsgspecError:
        return False
    numbers = (*c.wxyz, *c.position, c.fov, c.near, c.far, *c.look_at, *c.up_direction)
    return all(map(math.isfinite, numbers))
