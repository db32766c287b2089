"""Parse one CRCL document with lxml, hardened against hostile XML.

Refused before the parser sees a byte: a document over ``MAX_DOCUMENT_BYTES``, one
that is not UTF-8 (a UTF-16 byte-order mark, NUL bytes, a declared encoding other than
UTF-8 or ASCII) and any ``<!DOCTYPE`` or ``<!ENTITY`` (upper or lower case, anywhere,
even in a comment): CRCL needs no DTD, and without one there is no entity to expand, so
neither XXE (an external entity reading a local file or a URL) nor "billion laughs"
(nested entity expansion) can start. The lxml parser itself is configured not to
resolve entities, load DTDs or touch the network, and to keep its size limits
(``huge_tree=False``); comments and processing instructions are dropped. A DOCTYPE
that slipped past the byte scan would still be refused after parsing.
"""

from __future__ import annotations

import re
import threading
from typing import Final

from lxml import etree

from ...protocol.limits import default
from .errors import CrclSyntaxError

__all__ = ["MAX_DOCUMENT_BYTES", "parse_xml"]

MAX_DOCUMENT_BYTES: Final = default("crcl", "max_document_bytes")
"""The largest document accepted [bytes] (1 MiB), the splitter's default limit too."""

_FORBIDDEN = re.compile(rb"<!\s*(DOCTYPE|ENTITY)", re.IGNORECASE)
_DECLARED = re.compile(rb"\A(?:\xef\xbb\xbf)?\s*<\?xml\b[^>]*?\bencoding\s*=\s*([\"'])(.*?)\1")
_UTF8_NAMES = {b"utf-8", b"utf8", b"us-ascii", b"ascii"}
_local = threading.local()


def _parser() -> etree.XMLParser:
    parser: etree.XMLParser | None = getattr(_local, "parser", None)
    if parser is None:  # one per thread: an lxml parser must not be shared between threads
        parser = etree.XMLParser(
            resolve_entities=False,
            no_network=True,
            load_dtd=False,
            dtd_validation=False,
            huge_tree=False,
            remove_comments=True,
            remove_pis=True,
            collect_ids=False,
        )
        _local.parser = parser
    return parser


def parse_xml(
    doc: bytes, roots: tuple[str, ...], max_bytes: int = MAX_DOCUMENT_BYTES
) -> etree._Element:
    """The root element of ``doc``, refused unless safe, well-formed and one of ``roots``.

    Args:
        doc: One whole document, UTF-8, with or without an ``<?xml?>`` declaration.
        roots: The root element names accepted (local names; a prefix is ignored).
        max_bytes: The largest document accepted [bytes].

    Raises:
        CrclSyntaxError: Too large, not UTF-8, a DOCTYPE or entity declaration,
            malformed XML, or another root element.
    """
    if not isinstance(doc, (bytes, bytearray, memoryview)):
        raise TypeError(f"a CRCL document is bytes, not {type(doc).__name__}")
    doc = bytes(doc)
    if len(doc) > max_bytes:
        raise CrclSyntaxError(f"document of {len(doc)} bytes is over the limit of {max_bytes}")
    if doc[:2] in (b"\xff\xfe", b"\xfe\xff") or b"\x00" in doc:
        raise CrclSyntaxError("document is not UTF-8 (UTF-16 or NUL bytes); CRCL here is UTF-8")
    declared = _DECLARED.match(doc)
    if declared and declared.group(2).lower() not in _UTF8_NAMES:
        name = declared.group(2).decode("ascii", "replace")
        raise CrclSyntaxError(f"encoding {name!r} is not accepted: documents must be UTF-8")
    forbidden = _FORBIDDEN.search(doc)
    if forbidden:
        what = forbidden.group(1).decode().upper()
        raise CrclSyntaxError(
            f"<!{what}> refused: CRCL documents may not have a DOCTYPE or declare entities"
        )
    try:
        root = etree.fromstring(doc, _parser())
    except etree.XMLSyntaxError as error:
        raise CrclSyntaxError(f"malformed XML: {error.msg[:160]}") from None
    if root.getroottree().docinfo.doctype:
        raise CrclSyntaxError("DOCTYPE refused: CRCL documents may not have a DOCTYPE")
    tag = root.tag
    local = tag.rpartition("}")[2] if isinstance(tag, str) else ""
    if local not in roots:
        expected = " or ".join(f"<{name}>" for name in roots)
        raise CrclSyntaxError(f"root element <{local[:40]}> is not {expected}")
    return root
