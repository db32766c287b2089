"""Reading the stamp, names and positions of a serialized ``sensor_msgs/JointState``, quickly.

Pure: bytes in, values out, for the two wire formats a bag holds: ROS 2's CDR
(little-endian, what every ROS 2 publisher on x86 and ARM sends) and ROS 1's
serialization. A player reads hundreds of thousands of these, and nearly all
repeat the previous message's joint names, so ``JointStateDecoder`` compares
the names' bytes with the last ones it parsed and reuses the parsed names when
they match, and unpacks the positions with a ``struct`` kept per count (for a
handful of joints, several times quicker than numpy or a general
deserializer). ``decode`` returns None for big-endian CDR, so the caller can
fall back on a general deserializer.
"""

from __future__ import annotations

import struct
from functools import cache

__all__ = ["Decoded", "JointStateDecoder"]

_CDR_STAMP = struct.Struct("<iI")  # int32 sec, uint32 nanosec (after the 4-byte header)
_ROS1_STAMP = struct.Struct("<II")  # uint32 sec, uint32 nsec (after the uint32 seq)
_UINT32 = struct.Struct("<I")

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
            at = 16 + _UINT32.unpack_from(raw, 12)[0]  # past the frame id
        else:
            if len(raw) < 16 or raw[0] != 0 or raw[1] != 1:
                return None
            sec, nanosec = _CDR_STAMP.unpack_from(raw, 4)
            at = 16 + _UINT32.unpack_from(raw, 12)[0]
            at += -at % 4  # CDR aligns each number to its size, from the payload's start at 4
        (count,) = _UINT32.unpack_from(raw, at)
        names, at = self._read_names(raw, at + 4, count)
        if not self.ros1:
            at += -at % 4
        (n,) = _UINT32.unpack_from(raw, at)
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
            (length,) = _UINT32.unpack_from(raw, at)
            end = at + 4 + length
            if end > len(raw):
                raise ValueError("a joint name runs past the message")
            text = raw[at + 4 : end if self.ros1 else end - 1]  # CDR counts a closing NUL
            parsed.append(bytes(text).decode())
            at = end
        self._names, self._names_bytes = tuple(parsed), bytes(raw[start:at])
        return self._names, at
