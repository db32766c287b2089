"""What a piece of XML markup at a position in a buffer is: the splitter's lookahead.

Each recogniser answers True, False, or None when the bytes so far are too few to tell
(the splitter then waits for more). They look at most ``MAX_NAME`` bytes ahead.
"""

from __future__ import annotations

import re
from collections.abc import Collection
from typing import Final

from c2rviz.errors import shown

NOT_SPACE: Final = re.compile(rb"[^ \t\r\n]")
CONTROL: Final = re.compile(rb"[\x00-\x08\x0b\x0c\x0e-\x1f]")
"""Bytes XML 1.0 never allows (C0 controls but tab, LF, CR): binary data."""
TAG_STOP: Final = re.compile(rb"[>\"']")
TOKEN: Final = re.compile(
    rb"<(?:(?P<end>/[^>]*>)|(?P<start>[A-Za-z_:\x80-\xff](?:[^>\"']|\"[^\"]*\"|'[^']*')*>)"
    rb"|!--.*?-->|!\[CDATA\[.*?\]\]>|\?.*?\?>)",
    re.DOTALL,
)
"""One whole tag (group ``end`` or ``start``), comment, CDATA section or PI."""
PLAIN_TAG: Final = re.compile(rb"<(?:(/)[^>]*|[A-Za-z_:\x80-\xff][^>]*?(/?))>")
"""A tag as ``TOKEN`` reads it where there are no quotes, comments, CDATA or PIs:
groups (``/``, ``""``) an end tag, (``""``, ``""``) a start tag, (``""``, ``/``) an
empty-element tag."""
NAME: Final = re.compile(rb"<([A-Za-z_:\x80-\xff][^ \t\r\n/>!?<\"'=]*)")
MAX_NAME: Final = 256
SPACE: Final = b" \t\r\n"
BOM: Final = b"\xef\xbb\xbf"


def starts(buf: bytearray, i: int, token: bytes) -> bool | None:
    """Whether ``buf[i:]`` starts with ``token``; None if too short to tell yet."""
    have = bytes(buf[i : i + len(token)])
    if have == token:
        return True
    if len(have) < len(token) and token.startswith(have):
        return None
    return False


def root_at(buf: bytearray, i: int, roots: Collection[bytes]) -> bool | None:
    """Whether the start tag of one of ``roots`` (local names, any prefix) is at ``i``."""
    if i + 1 >= len(buf):
        return None
    match = NAME.match(buf, i)
    if match is None:
        return False
    end = match.end()
    if end == len(buf):
        return None if end - i < MAX_NAME else False
    if buf[end] not in SPACE and buf[end] not in b"/>":
        return False
    return match.group(1).rpartition(b":")[2] in roots


def declaration_at(buf: bytearray, i: int) -> bool | None:
    """Whether an ``<?xml ...?>`` declaration begins at ``i`` (not ``<?xml-foo``)."""
    found = starts(buf, i, b"<?xml")
    if not found:
        return found
    if i + 5 >= len(buf):
        return None
    return buf[i + 5] in SPACE


def shown_at(buf: bytearray, i: int) -> str:
    """The text or tag at ``i``, quoted and cut (up to its first ``>`` or next ``<``)."""
    piece = bytes(buf[i : i + 41])
    if piece.startswith(b"<"):
        piece = piece.split(b">")[0] + b">" if b">" in piece else piece
    else:
        piece = piece.split(b"<")[0]
    return shown(piece.decode("utf-8", "replace"), 40)
