"""Split a CRCL byte stream into documents (sans I/O: bytes in, documents out).

CRCL sends XML documents back to back with no length prefix and no terminator. The
splitter scans the markup just enough to find where each document's root element
ends (its matching end tag, any prefix, or a self-closed root), in time linear in the
bytes fed (it never rescans) and in memory bounded by ``max_bytes`` plus one chunk.
Between documents it skips whitespace, a UTF-8 byte-order mark, comments and
processing instructions; a document's bytes run from its ``<?xml?>`` declaration (or,
without one, from its root's ``<``) to the end of its root. Nothing is validated
beyond that: ``documents.parse_command`` judges each document.

Errors come out in the stream's order among the documents, as ``CrclFramingError``:

Re-synchronised (``recoverable``: the splitter skips to the next ``<?xml`` or root start
tag of a CRCL document and goes on):
    - text that cannot start a document (``joints 0 0 0``, stray words);
    - a start tag whose name is not a CRCL root (``<Foo>``), an end tag outside a
      document;
    - a second ``<?xml?>`` declaration before the root (the new one starts the document).

Not re-synchronised (the splitter is ``closed``; the driver reports the error and
closes the connection, since what follows cannot be trusted to be where it seems):
    - a document growing past ``max_bytes`` (by default 1 MiB), complete or not;
    - binary data: a byte XML never allows (C0 controls other than tab, CR, LF);
    - a ``<!DOCTYPE`` or any ``<!`` markup declaration (entity tricks start there).

A half-sent document is not an error here (no clocks inside): ``pending_bytes`` and
``started_at`` (the ``now`` passed with the chunk it began in) let the driver time it
out, and ``discard_pending`` drops it and skips to the next document.
"""

from __future__ import annotations

import operator
from itertools import accumulate, islice
from typing import Final

from .documents import MAX_DOCUMENT_BYTES
from .errors import CrclFramingError
from .markup import (
    BOM,
    CONTROL,
    NAME,
    NOT_SPACE,
    PLAIN_TAG,
    TAG_STOP,
    TOKEN,
    declaration_at,
    root_at,
    shown_at,
)
from .markup import starts as _starts

CRCL_ROOTS: Final = ("CRCLCommandInstance", "CRCLProgram", "CRCLStatus")

_LT, _SLASH, _BANG, _QUESTION = 0x3C, 0x2F, 0x21, 0x3F
(_BETWEEN, _RESYNC, _CONTENT, _COMMENT, _PI, _CDATA, _START_TAG, _END_TAG) = range(8)
_ENDS = {_COMMENT: b"-->", _PI: b"?>", _CDATA: b"]]>"}
_STEP = {(b"/", b""): -1, (b"", b""): 1, (b"", b"/"): 0}  # a PLAIN_TAG's change of depth


class DocumentSplitter:
    """Cut a byte stream into CRCL documents as it arrives (see the module docstring).

    Args:
        max_bytes: The largest document accepted [bytes], declaration included.
        roots: The root element names that start a document (a prefix is ignored).
    """

    def __init__(self, max_bytes: int = MAX_DOCUMENT_BYTES, roots: tuple[str, ...] = CRCL_ROOTS):
        self.max_bytes = max_bytes
        self.roots = roots
        self._roots = {root.encode() for root in roots}
        self._buf = bytearray()
        self._dropped = 0  # stream offset of _buf[0]
        self._pos = 0  # where scanning resumes
        self._start = -1  # first byte of the pending document, or -1
        self._item = -1  # first byte of an unfinished piece of markup, or -1
        self._state = _BETWEEN
        self._back = _BETWEEN  # state to return to after a comment or PI
        self._root_tag = False  # the start tag being scanned is the root's
        self._quote = b""
        self._depth = 0
        self._closed = False
        self._started_at: float | None = None

    @property
    def closed(self) -> bool:
        """True after an error the stream cannot be re-synchronised after."""
        return self._closed

    @property
    def pending_bytes(self) -> int:
        """Bytes held of a document (or piece of markup) not yet complete."""
        held = [index for index in (self._start, self._item) if index >= 0]
        return len(self._buf) - min(held) if held else 0

    @property
    def started_at(self) -> float | None:
        """The ``now`` of the chunk the pending bytes began in; None if none pending."""
        return self._started_at

    def feed(self, data: bytes, now: float = 0.0) -> list[bytes | CrclFramingError]:
        """Take the next chunk; return the documents (bytes) and errors it completes.

        Args:
            data: The next bytes of the stream, as received.
            now: The caller's clock [s] (e.g. ``loop.time()``), kept as ``started_at``.

        Returns:
            Whole documents and ``CrclFramingError``s, in stream order; nothing
            once ``closed``.
        """
        out: list[bytes | CrclFramingError] = []
        if self._closed or not data:
            return out
        bad = CONTROL.search(data)
        self._buf += data if bad is None else data[: bad.start()]
        self._run(out)
        if bad is not None and not self._closed:
            offset = self._dropped + len(self._buf)
            self._fail(out, f"binary data (byte 0x{data[bad.start()]:02x} at offset {offset})")
        elif not self._closed and self.pending_bytes > self.max_bytes:
            self._fail(out, f"document over the limit of {self.max_bytes} bytes")
        self._compact()
        if self.pending_bytes == 0:
            self._started_at = None
        elif self._started_at is None:
            self._started_at = now
        return out

    def discard_pending(self) -> int:
        """Drop the pending document (e.g. it stalled) and skip to the next; bytes dropped."""
        dropped = self.pending_bytes
        if dropped and not self._closed:
            self._pos = len(self._buf)
            self._start = self._item = -1
            self._state = _RESYNC
            self._compact()
            self._started_at = None
        return dropped

    def _compact(self) -> None:
        held = [index for index in (self._start, self._item) if index >= 0]
        keep = min(held) if held else self._pos
        if keep:
            del self._buf[:keep]
            self._dropped += keep
            self._pos -= keep
            self._start = self._start - keep if self._start >= 0 else -1
            self._item = self._item - keep if self._item >= 0 else -1

    def _fail(self, out: list[bytes | CrclFramingError], problem: str) -> None:
        out.append(CrclFramingError(f"{problem}; closing the stream", recoverable=False))
        self._closed = True
        self._buf.clear()
        self._pos = 0
        self._start = self._item = -1

    def _skip(self, out: list[bytes | CrclFramingError], problem: str, resume: int) -> None:
        out.append(CrclFramingError(f"{problem}; skipping to the next document", recoverable=True))
        self._start = self._item = -1
        self._pos = resume
        self._state = _RESYNC

    def _run(self, out: list[bytes | CrclFramingError]) -> None:
        buf = self._buf
        while not self._closed:
            state, pos = self._state, self._pos
            if state == _BETWEEN:
                found = NOT_SPACE.search(buf, pos)
                if found is None:
                    self._pos = len(buf)
                    return
                i = self._pos = found.start()
                if buf[i] == _LT:
                    if not self._markup_between(out, i):
                        return
                elif self._start < 0 and _starts(buf, i, BOM) is not False:
                    if _starts(buf, i, BOM) is None:
                        return
                    self._pos = i + 3
                else:
                    self._skip(out, f"text outside a document: {shown_at(self._buf, i)}", i)
            elif state == _RESYNC:
                i = buf.find(b"<", pos)
                if i < 0:
                    self._pos = len(buf)
                    return
                declaration = declaration_at(self._buf, i)
                root = root_at(self._buf, i, self._roots) if declaration is False else False
                if declaration is None or root is None:
                    self._pos = self._item = i
                    return
                self._item = -1
                self._pos, self._state = (i, _BETWEEN) if declaration or root else (i + 1, _RESYNC)
            elif state == _CONTENT:
                if self._skim(out):
                    continue
                i = buf.find(b"<", self._pos)
                if i < 0:
                    self._pos = len(buf)
                    return
                self._pos = i
                if not self._markup_inside(out, i):
                    return
            elif state in _ENDS:
                end = _ENDS[state]
                i = buf.find(end, pos)
                if i < 0:
                    self._pos = max(pos, len(buf) - len(end) + 1)
                    return
                self._pos, self._state, self._item = i + len(end), self._back, -1
            elif state == _START_TAG:
                if not self._scan_start_tag(out):
                    return
            else:  # _END_TAG
                i = buf.find(b">", pos)
                if i < 0:
                    self._pos = len(buf)
                    return
                self._depth -= 1
                self._close_tag(out, i + 1)

    def _markup_between(self, out: list[bytes | CrclFramingError], i: int) -> bool:
        """Classify markup at ``i`` outside a root element; False: wait for more bytes."""
        buf = self._buf
        if i + 1 >= len(buf):
            return False
        kind = buf[i + 1]
        if kind == _BANG:
            comment = _starts(buf, i, b"<!--")
            if comment is None:
                return False
            if not comment:
                self._fail(out, f"markup declaration {shown_at(self._buf, i)} refused (no DOCTYPE)")
                return True
            self._enter(_COMMENT, i, i + 4, _BETWEEN)
        elif kind == _QUESTION:
            declaration = declaration_at(self._buf, i)
            if declaration is None:
                return False
            if declaration:
                if self._start >= 0:
                    out.append(
                        CrclFramingError(
                            "a second <?xml?> declaration before the root element; "
                            "the new one starts the document",
                            recoverable=True,
                        )
                    )
                self._start = i
            self._enter(_PI, i, i + 2, _BETWEEN)
        elif kind == _SLASH:
            self._skip(out, f"end tag outside a document: {shown_at(self._buf, i)}", i + 1)
        else:
            root = root_at(self._buf, i, self._roots)
            if root is None:
                self._item = i
                return False
            if not root:
                expected = ", ".join(f"<{name}>" for name in self.roots)
                self._skip(
                    out,
                    f"{shown_at(self._buf, i)} does not start a CRCL document ({expected})",
                    i + 1,
                )
                return True
            if self._start < 0:
                self._start = i
            self._root_tag = True
            self._enter(_START_TAG, i, i + 1, _CONTENT)
        return True

    def _skim(self, out: list[bytes | CrclFramingError]) -> bool:
        """Step over whole tags, comments, CDATA and PIs with one regex each (the common
        case); True if that closed the root. Anything else, or a piece not all here
        yet, is left to the state machine."""
        if self._skim_plain(out):
            return True
        buf, pos, depth = self._buf, self._pos, self._depth
        while depth > 0:
            i = buf.find(b"<", pos)  # text is skipped by memchr, not by the regex
            token = TOKEN.match(buf, i) if i >= 0 else None
            if token is None:
                break
            pos = token.end()
            kind = token.lastgroup
            if kind == "end":
                depth -= 1
            elif kind == "start" and buf[pos - 2] != _SLASH:
                depth += 1
        self._pos, self._depth = pos, depth
        if depth:
            return False
        self._close_tag(out, pos)
        return True

    def _skim_plain(self, out: list[bytes | CrclFramingError]) -> bool:
        """``_skim`` without a Python step per tag, up to the first quote, comment, CDATA
        or PI (whose tags need ``TOKEN``): there every tag is ``PLAIN_TAG``, and the
        depth after each is a running sum, found in C (``accumulate``, ``indexOf``).
        The same tags, depths and cut as ``_skim``'s; True if the root closed."""
        buf, pos, depth = self._buf, self._pos, self._depth
        if depth <= 0:
            return False
        stop = len(buf)
        for special in (b'"', b"'", b"<!", b"<?"):
            found = buf.find(special, pos, stop)
            if found >= 0:
                stop = found
        end = buf.rfind(b">", pos, stop) + 1
        if end <= pos:
            return False
        kinds = PLAIN_TAG.findall(buf, pos, end)
        steps = list(map(_STEP.__getitem__, kinds))
        try:
            closing = operator.indexOf(accumulate(steps, initial=depth), 0)
        except ValueError:  # the root is still open at ``end``
            self._pos, self._depth = end, depth + sum(steps)
            return False
        tag = next(islice(PLAIN_TAG.finditer(buf, pos, end), closing - 1, None))
        self._pos, self._depth = tag.end(), 0
        self._close_tag(out, tag.end())
        return True

    def _markup_inside(self, out: list[bytes | CrclFramingError], i: int) -> bool:
        """Classify markup at ``i`` inside the root element; False: wait for more bytes."""
        buf = self._buf
        if i + 1 >= len(buf):
            return False
        kind = buf[i + 1]
        if kind == _BANG:
            comment, cdata = _starts(buf, i, b"<!--"), _starts(buf, i, b"<![CDATA[")
            if comment:
                self._enter(_COMMENT, i, i + 4, _CONTENT)
            elif cdata:
                self._enter(_CDATA, i, i + 9, _CONTENT)
            elif comment is None or cdata is None:
                return False
            else:
                self._fail(out, f"markup declaration {shown_at(self._buf, i)} refused (no DOCTYPE)")
        elif kind == _QUESTION:
            self._enter(_PI, i, i + 2, _CONTENT)
        elif kind == _SLASH:
            self._enter(_END_TAG, i, i + 2, _CONTENT)
        elif NAME.match(buf, i):
            self._root_tag = False
            self._enter(_START_TAG, i, i + 1, _CONTENT)
        else:
            self._pos = i + 1  # a stray '<' in text: not ours to judge; the parser will
        return True

    def _enter(self, state: int, item: int, pos: int, back: int) -> None:
        self._state, self._item, self._pos, self._back = state, item, pos, back
        self._quote = b""

    def _scan_start_tag(self, out: list[bytes | CrclFramingError]) -> bool:
        """Find the ``>`` ending a start tag, outside quoted values; False: wait."""
        buf = self._buf
        while True:
            if self._quote:
                i = buf.find(self._quote, self._pos)
                if i < 0:
                    self._pos = len(buf)
                    return False
                self._pos, self._quote = i + 1, b""
            found = TAG_STOP.search(buf, self._pos)
            if found is None:
                self._pos = len(buf)
                return False
            i = found.start()
            if buf[i] != 0x3E:  # a quote opens an attribute value
                self._pos, self._quote = i + 1, bytes(buf[i : i + 1])
                continue
            closed = buf[i - 1] == _SLASH
            if self._root_tag:
                self._depth = 0
            if not closed:
                self._depth += 1
            self._close_tag(out, i + 1)
            return True

    def _close_tag(self, out: list[bytes | CrclFramingError], end: int) -> None:
        """After a tag ending at ``end``: emit the document if its root is closed."""
        self._item = -1
        self._pos = end
        if self._depth > 0:
            self._state = _CONTENT
            return
        size = end - self._start
        if size > self.max_bytes:
            self._fail(out, f"document of {size} bytes is over the limit of {self.max_bytes}")
            return
        out.append(bytes(self._buf[self._start : end]))
        self._start = -1
        self._state = _BETWEEN
        self._started_at = None
