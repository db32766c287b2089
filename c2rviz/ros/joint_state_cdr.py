"""Reading the names, positions and stamp of a CDR ``sensor_msgs/msg/JointState``, quickly.

Pure: bytes in, values out. A player reads hundreds of thousands of these, and
nearly all repeat the previous message's joint names: ``JointStateDecoder``
compares the names' bytes with the last ones it parsed and reuses the parsed
names when they match, and unpacks the positions with a ``struct`` kept per
count (for a handful of joints, several times quicker than numpy). Little-endian
CDR only (what every ROS 2 publisher on x86 and ARM sends); ``decode`` returns
None for anything else so the caller can fall back on a general deserializer.
"""

from __future__ import annotations

import struct
from functools import cache

__all__ = ["Decoded", "JointStateDecoder"]

_STAMP = struct.Struct("<iI")
_UINT32 = struct.Struct("<I")

Decoded = tuple[int, tuple[str, ...], tuple[float, ...]]
"""(header stamp [ns], joint names, positions [rad or m])."""


@cache
def _doubles(count: int) -> struct.Struct:
    return struct.Struct(f"<{count}d")


class JointStateDecoder:
    """Decodes JointState CDR payloads, remembering the last joint names."""

    def __init__(self) -> None:
        self._names_bytes = b""
        self._names: tuple[str, ...] = ()

    def decode(self, raw: bytes | memoryview) -> Decoded | None:
        """Stamp, names and positions of one message, or None if it is not little-endian CDR.

        Raises:
            ValueError: the payload is shorter than its own lengths say (struct.error
                is a ValueError).
        """
        if len(raw) < 16 or raw[0] != 0 or raw[1] != 1:
            return None
        sec, nanosec = _STAMP.unpack_from(raw, 4)
        (frame_length,) = _UINT32.unpack_from(raw, 12)
        at = 16 + frame_length
        at += -at % 4
        (count,) = _UINT32.unpack_from(raw, at)
        at += 4
        start = at
        known = self._names_bytes
        if count == len(self._names) and count and bytes(raw[start : start + len(known)]) == known:
            names = self._names
            at = start + len(known)
        else:
            parsed = []
            for _ in range(count):
                at += -at % 4
                (length,) = _UINT32.unpack_from(raw, at)
                end = at + 4 + length
                if length == 0 or end > len(raw):
                    raise ValueError("a joint name runs past the message")
                parsed.append(bytes(raw[at + 4 : end - 1]).decode())
                at = end
            names = tuple(parsed)
            self._names, self._names_bytes = names, bytes(raw[start:at])
        at += -at % 4
        (n,) = _UINT32.unpack_from(raw, at)
        at += 4
        positions: tuple[float, ...] = ()
        if n:
            at += (4 - at) % 8  # doubles align to 8 in the payload, which starts at 4
            positions = _doubles(n).unpack_from(raw, at)  # struct.error if it runs past
        return sec * 1_000_000_000 + nanosec, names, positions
