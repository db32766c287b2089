"""CDR encoding of ROS 2 messages given as plain dicts, compiled once per type, and the
quick decoding of a serialized JointState.

``CdrEncoder(typestore).encode(msgtype, message)`` returns the bytes a ROS 2
publisher puts on the wire (little-endian CDR after its 4-byte encapsulation
header): what ``rosbags``' ``typestore.serialize_cdr`` makes from a message
object, byte for byte, without building the objects first.

Each type is compiled on first use, from the typestore's field definitions,
into one Python function with every nested field inlined (as rosbags compiles
its own serializers): runs of fixed-size numbers (a ``Time``, a ``Transform``)
are packed with one ``struct`` call, whose padding is chosen by where the run
starts (mod 8). The generated source holds only dict keys (as ``repr``
literals), struct codes and local names, never a text from a message.

Dicts take the rosbridge JSON shape: every field of the type by name (a
missing one is an error), numbers as ``int``/``float``/``bool``, numeric
arrays as lists, tuples or numpy arrays, ``uint8``/``byte`` arrays also as
``bytes`` or, as rosbridge sends them, a base64 string.

``JointStateDecoder`` reads the stamp, names and positions of a serialized
``sensor_msgs/JointState``, quickly. Pure: bytes in, values out, for the two wire formats
a bag holds: ROS 2's CDR (little-endian, what every ROS 2 publisher on x86 and ARM sends)
and ROS 1's serialization. A player reads hundreds of thousands of these, and nearly all
repeat the previous message's joint names, so ``JointStateDecoder`` compares the names'
bytes with the last ones it parsed and reuses the parsed names when they match, and
unpacks the positions with a ``struct`` kept per count (for a handful of joints, several
times quicker than numpy or a general deserializer). ``decode`` returns None for
big-endian CDR, so the caller can fall back on a general deserializer.
"""

from __future__ import annotations

import base64
import struct
from collections.abc import Callable
from functools import cache
from typing import Any

import numpy as np
from rosbags.interfaces import Nodetype
from rosbags.typesys.store import Typestore

from .errors import MessageError

Encode = Callable[[bytearray, Any], None]

_HEADER = b"\x00\x01\x00\x00"  # CDR, little-endian
_CODES = {
    "bool": "?",
    "byte": "B",
    "char": "B",
    "int8": "b",
    "uint8": "B",
    "int16": "h",
    "uint16": "H",
    "int32": "i",
    "uint32": "I",
    "int64": "q",
    "uint64": "Q",
    "float32": "f",
    "float64": "d",
}
_OCTETS = frozenset({"byte", "char", "uint8"})
_UINT32 = struct.Struct("<I").pack
_FILLER = "structure_needs_at_least_one_member"

_STRINGS: dict[str, bytes] = {}  # recent strings, encoded (frame and joint names recur)
_STRINGS_KEPT = 4096
_STRING_KEPT_LENGTH = 256


def _string(buf: bytearray, value: str) -> None:
    """A string: aligned uint32 length (with the NUL), UTF-8 bytes, NUL."""
    data = _STRINGS.get(value)
    if data is None:
        raw = value.encode()
        data = _UINT32(len(raw) + 1) + raw + b"\x00"
        if len(raw) <= _STRING_KEPT_LENGTH:
            if len(_STRINGS) >= _STRINGS_KEPT:
                _STRINGS.clear()
            _STRINGS[value] = data
    gap = -len(buf) % 4  # the header is 4 bytes, so the payload aligns as the buffer does
    if gap:
        buf += b"\x00" * gap
    buf += data


def _numbers(buf: bytearray, value: Any, code: str, length: int) -> None:
    """A numeric sequence (``length`` -1: uint32 count first) or fixed-length array."""
    if code == "o":  # octets: bytes, a list of ints, or rosbridge's base64 text
        value = base64.b64decode(value, validate=True) if isinstance(value, str) else bytes(value)
        code = "B"
    n = len(value)
    if length < 0:
        gap = -len(buf) % 4
        if gap:
            buf += b"\x00" * gap
        buf += _UINT32(n)
    elif n != length:
        raise ValueError(f"{n} values for an array of {length}")
    if not n:
        return
    size = struct.calcsize(code)
    gap = (4 - len(buf)) % size
    if gap:
        buf += b"\x00" * gap
    if isinstance(value, bytes):
        buf += value
    elif isinstance(value, np.ndarray):
        buf += np.ascontiguousarray(value, dtype="<" + code).tobytes()
    else:
        buf += struct.pack(f"<{n}{code}", *value)


def _packers(codes: str) -> tuple[Callable[..., bytes], ...]:
    """``struct`` packers of a run of numbers, one per start offset mod 8 (with padding)."""
    packers = []
    for start in range(8):
        fmt, at = "<", start
        for code in codes:
            size = struct.calcsize(code)
            gap = -at % size
            fmt += "x" * gap + code
            at += gap + size
        packers.append(struct.Struct(fmt).pack)
    return tuple(packers)


class _Source:
    """The generated source of one type's encoder."""

    def __init__(self, fielddefs: Any) -> None:
        self.fielddefs = fielddefs
        self.lines: list[str] = []
        self.names: dict[str, Any] = {"_string": _string, "_numbers": _numbers}
        self.count = 0
        self.run: list[tuple[str, str]] = []  # pending fixed-size numbers: (code, expression)
        self.run_indent = ""

    def local(self) -> str:
        self.count += 1
        return f"v{self.count}"

    def emit(self, indent: str, line: str) -> None:
        self.flush()
        self.lines.append(indent + line)

    def flush(self) -> None:
        """Pack the pending run of numbers with one struct call."""
        if not self.run:
            return
        codes = "".join(code for code, _ in self.run)
        name = f"P{len(self.names)}"
        self.names[name] = _packers(codes)
        values = ", ".join(expression for _, expression in self.run)
        self.run = []
        self.lines.append(f"{self.run_indent}buf += {name}[(len(buf) - 4) % 8]({values})")

    def fields(self, msgtype: str) -> list[tuple[str, tuple[Any, Any]]]:
        try:
            return list(self.fielddefs[msgtype][1])
        except KeyError:
            raise MessageError(f"unknown message type {msgtype!r}") from None

    def numbers_only(self, msgtype: str) -> bool:
        """Whether a type holds only fixed-size numbers (at any depth)."""
        return all(
            (kind == Nodetype.BASE and args[0] in _CODES)
            or (kind == Nodetype.NAME and self.numbers_only(args))
            for _, (kind, args) in self.fields(msgtype)
        )

    def message(self, msgtype: str, value: str, indent: str) -> None:
        for name, desc in self.fields(msgtype):
            if name == _FILLER:  # rosbags' stand-in field of an empty type: rosbridge sends {}
                self.field(desc, f"{value}.get({name!r}, 0)", indent)
            else:
                self.field(desc, f"{value}[{name!r}]", indent)

    def field(self, desc: tuple[Any, Any], expression: str, indent: str) -> None:
        kind, args = desc
        if kind == Nodetype.BASE and args[0] in _CODES:
            if self.run and self.run_indent != indent:
                self.flush()
            self.run.append((_CODES[args[0]], expression))
            self.run_indent = indent
        elif kind == Nodetype.BASE and args[0] == "string":
            self.emit(indent, f"_string(buf, {expression})")
        elif kind == Nodetype.NAME and self.numbers_only(args):  # joins the run, no local
            self.message(args, expression, indent)
        elif kind == Nodetype.NAME:
            local = expression
            if not expression.isidentifier():
                local = self.local()
                self.emit(indent, f"{local} = {expression}")
            self.message(args, local, indent)
        elif kind in (Nodetype.ARRAY, Nodetype.SEQUENCE):
            length = -1 if kind == Nodetype.SEQUENCE else int(args[1])
            self.array(args[0], expression, length, indent)
        else:
            raise MessageError(f"field type {args!r} is not supported")

    def array(self, inner: tuple[Any, Any], expression: str, length: int, indent: str) -> None:
        kind, args = inner
        if kind == Nodetype.BASE and args[0] in _CODES:
            code = "o" if args[0] in _OCTETS else _CODES[args[0]]
            self.emit(indent, f"_numbers(buf, {expression}, {code!r}, {length})")
            return
        local, item = self.local(), self.local()
        self.emit(indent, f"{local} = {expression}")
        if length < 0:
            self.emit(indent, "buf += b'\\x00' * (-len(buf) % 4)")
            self.emit(indent, f"buf += _UINT32(len({local}))")
            self.names["_UINT32"] = _UINT32
        else:
            wrong = f"ValueError('{length} values needed, not ' + str(len({local})))"
            self.emit(indent, f"if len({local}) != {length}:")
            self.emit(indent, f"    raise {wrong}")
        self.emit(indent, f"for {item} in {local}:")
        self.field(inner, item, indent + "    ")
        self.flush()


class CdrEncoder:
    """Dict -> CDR bytes for the types of one typestore, each compiled on first use."""

    def __init__(self, typestore: Typestore) -> None:
        """Encode the types ``typestore`` defines (for instance ``Stores.ROS2_HUMBLE``)."""
        self.fielddefs = typestore.fielddefs
        self._encoders: dict[str, Encode] = {}

    def encode(self, msgtype: str, message: Any) -> bytearray:
        """The CDR bytes of ``message`` (a dict of type ``msgtype``).

        Raises:
            MessageError: an unknown type, a missing field or a value of the wrong kind.
        """
        encode = self._encoders.get(msgtype) or self.compile(msgtype)
        buf = bytearray(_HEADER)
        try:
            encode(buf, message)
        except KeyError as exc:
            raise MessageError(f"{msgtype}: a message lacks field {exc.args[0]!r}") from None
        except (TypeError, ValueError, AttributeError, struct.error, OverflowError) as exc:
            raise MessageError(f"{msgtype}: a value does not fit its field: {exc}") from None
        return buf

    def compile(self, msgtype: str) -> Encode:
        """The encoder of ``msgtype``, made once (``encode`` calls it when needed).

        Raises:
            MessageError: an unknown type, or a field type CDR encoding here does not know.
        """
        source = _Source(self.fielddefs)
        source.message(msgtype, "message", "    ")
        source.flush()
        text = "\n".join(["def encode(buf, message):", *source.lines, "    return None"])
        namespace = dict(source.names)
        exec(compile(text, f"<cdr encoder of {msgtype}>", "exec"), namespace)  # noqa: S102
        encode: Encode = namespace["encode"]
        encode.__doc__ = text  # the source, for a reader who wonders
        self._encoders[msgtype] = encode
        return encode


_CDR_STAMP = struct.Struct("<iI")  # int32 sec, uint32 nanosec (after the 4-byte header)
_ROS1_STAMP = struct.Struct("<II")  # uint32 sec, uint32 nsec (after the uint32 seq)
_UINT32_STRUCT = struct.Struct("<I")

Decoded = tuple[int, tuple[str, ...], tuple[float, ...]]
"""(header stamp [ns], joint names, positions [rad or m])."""


@cache
def _doubles(count: int) -> struct.Struct:
    return struct.Struct(f"<{count}d")


class JointStateDecoder:
    """Decodes one bag's JointState messages, remembering the last joint names."""

    def __init__(self, ros1: bool = False) -> None:
        """Decode ROS 1 serialization if ``ros1``, else ROS 2 CDR."""
        self.ros1 = ros1
        self._names_bytes = b""
        self._names: tuple[str, ...] = ()

    def decode(self, raw: bytes | memoryview) -> Decoded | None:
        """Stamp, names and positions of one message; None for CDR that is not little-endian.

        Raises:
            ValueError: the bytes are shorter than their own lengths say, or a name is
                not UTF-8.
        """
        try:
            return self._decode(raw)
        except struct.error as exc:
            raise ValueError(f"a JointState cut short: {exc}") from None

    def _decode(self, raw: bytes | memoryview) -> Decoded | None:
        if self.ros1:
            sec, nanosec = _ROS1_STAMP.unpack_from(raw, 4)
            at = 16 + _UINT32_STRUCT.unpack_from(raw, 12)[0]  # past the frame id
        else:
            if len(raw) < 16 or raw[0] != 0 or raw[1] != 1:
                return None
            sec, nanosec = _CDR_STAMP.unpack_from(raw, 4)
            at = 16 + _UINT32_STRUCT.unpack_from(raw, 12)[0]
            at += -at % 4  # CDR aligns each number to its size, from the payload's start at 4
        (count,) = _UINT32_STRUCT.unpack_from(raw, at)
        names, at = self._read_names(raw, at + 4, count)
        if not self.ros1:
            at += -at % 4
        (n,) = _UINT32_STRUCT.unpack_from(raw, at)
        at += 4
        positions: tuple[float, ...] = ()
        if n:
            if not self.ros1:
                at += (4 - at) % 8  # a double aligns to 8 in the payload, which starts at 4
            positions = _doubles(n).unpack_from(raw, at)  # struct.error if it runs past
        return sec * 1_000_000_000 + nanosec, names, positions

    def _read_names(
        self, raw: bytes | memoryview, start: int, count: int
    ) -> tuple[tuple[str, ...], int]:
        """The ``count`` names from ``start``, and where they end."""
        known = self._names_bytes
        if count and count == len(self._names) and raw[start : start + len(known)] == known:
            return self._names, start + len(known)
        parsed = []
        at = start
        for _ in range(count):
            if not self.ros1:
                at += -at % 4
            (length,) = _UINT32_STRUCT.unpack_from(raw, at)
            end = at + 4 + length
            if end > len(raw):
                raise ValueError("a joint name runs past the message")
            text = raw[at + 4 : end if self.ros1 else end - 1]  # CDR counts a closing NUL
            parsed.append(bytes(text).decode())
            at = end
        self._names, self._names_bytes = tuple(parsed), bytes(raw[start:at])
        return self._names, at
