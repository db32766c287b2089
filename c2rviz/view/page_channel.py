"""The local channel between the command process and the page process: framed msgpack.

A message is a list whose first item names it (``["frame", ...]``, ``["line", robot,
text]``); ``encode`` packs it with msgspec's msgpack and prefixes its length (4 bytes,
big-endian), ``FrameReader`` takes bytes as they come and hands back whole messages.

Why a socket pair and not shared memory: what changes per frame is small (a few
joint values per robot, now and then a marker or a line of text), it is ordered (a
marker cleared, then a new one), and it goes both ways (the page's sliders come
back). A stream gives order, back-pressure (the sender sees its buffer grow and
can drop to a snapshot) and end-of-file when the other side dies, which is how the
command process notices a crashed page; shared memory would need its own
sequencing, wake-ups and liveness checks for no gain at these sizes.
"""

from __future__ import annotations

from typing import Any

import msgspec
import numpy as np

from ..errors import C2rvizError

MAX_MESSAGE = 64 << 20
"""Largest message either side accepts [bytes] (a snapshot of many robots' markers)."""

_HEADER = 4


def _plain(value: object) -> object:
    """numpy's numbers and arrays as msgpack's (a joint value may be a ``np.float64``)."""
    if isinstance(value, np.generic | np.ndarray):
        return value.tolist()
    raise NotImplementedError(f"a page message cannot carry {type(value).__name__}")


_encoder = msgspec.msgpack.Encoder(enc_hook=_plain)
_decoder = msgspec.msgpack.Decoder(list)


class ChannelError(C2rvizError):
    """The other side sent something that is not a message of the channel."""


def encode(message: list[Any]) -> bytes:
    """``message`` framed for the channel: its length, then its msgpack bytes."""
    try:
        body = _encoder.encode(message)
    except (TypeError, NotImplementedError) as exc:
        raise ChannelError(str(exc)) from None
    if len(body) > MAX_MESSAGE:
        raise ChannelError(f"a page message of {len(body)} bytes is over {MAX_MESSAGE}")
    return len(body).to_bytes(_HEADER, "big") + body


class FrameReader:
    """Whole messages out of a byte stream fed in pieces (``feed``)."""

    def __init__(self) -> None:
        self._buffer = bytearray()

    def feed(self, data: bytes) -> list[list[Any]]:
        """Take ``data``; return the messages it completes, oldest first.

        Raises:
            ChannelError: a length over ``MAX_MESSAGE``, or bytes that are not msgpack
                of a list (the channel cannot go on: the caller closes it).
        """
        buffer = self._buffer
        buffer += data
        out: list[list[Any]] = []
        start = 0
        while len(buffer) - start >= _HEADER:
            size = int.from_bytes(buffer[start : start + _HEADER], "big")
            if size > MAX_MESSAGE:
                raise ChannelError(f"a page message says it is {size} bytes (over {MAX_MESSAGE})")
            end = start + _HEADER + size
            if len(buffer) < end:
                break
            try:
                message = _decoder.decode(bytes(buffer[start + _HEADER : end]))
            except msgspec.DecodeError as exc:
                raise ChannelError(f"a page message is not msgpack of a list: {exc}") from None
            if not message or not isinstance(message[0], str):
                raise ChannelError("a page message does not start with its kind")
            out.append(message)
            start = end
        del buffer[:start]
        return out
