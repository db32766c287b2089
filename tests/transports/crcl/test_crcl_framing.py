"""The document splitter: streams as CRCL senders write them, and streams that go wrong."""

from __future__ import annotations

from typing import cast

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from support import examples

from c2rviz.transports.crcl import CrclFramingError, DocumentSplitter, parse_command

XSI = 'xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"'
DECLARATION = b'<?xml version="1.0" encoding="UTF-8"?>'


def command(command_id: int, kind: str = "GetStatusType", prefix: str = "xsi") -> bytes:
    return (
        f'<CRCLCommandInstance xmlns:{prefix}="http://www.w3.org/2001/XMLSchema-instance">\n'
        f'  <CRCLCommand {prefix}:type="{kind}">\n    <CommandID>{command_id}</CommandID>\n'
        f"  </CRCLCommand>\n</CRCLCommandInstance>"
    ).encode()


A = DECLARATION + b"\n" + command(1, "InitCanonType")
B = command(2, prefix="p")
C = DECLARATION + b"<!-- prolog comment --><?pi x?>\n" + command(3)
TRICKY = (
    b'<n:CRCLCommandInstance xmlns:n="urn:x" ' + XSI.encode() + b' note="a>b" other=\'"/>\'>'
    b"<!-- </n:CRCLCommandInstance> --><?pi </n:CRCLCommandInstance>?>"
    b'<CRCLCommand xsi:type="MessageType"><CommandID>4</CommandID>'
    b"<Message><![CDATA[</n:CRCLCommandInstance> <x/>]]> 1 > 0</Message></CRCLCommand>"
    b"</n:CRCLCommandInstance >"
)
SELF_CLOSED = b"<CRCLStatus/>"

GOOD_STREAMS = [
    ("one", A, [A]),
    ("three-in-one-chunk", A + B + C, [A, B, C]),
    ("whitespace-between", b"\r\n  " + A + b"\n\n\t" + B + b"\n", [A, B]),
    ("trailing-comments-dropped", A + b"<!-- done -->\n" + B + b"<?pi?>", [A, B]),
    ("prolog-kept-from-declaration", b"<!-- x -->" + C, [C]),
    ("tricky-markup", TRICKY + A, [TRICKY, A]),
    ("self-closed-root", SELF_CLOSED + B, [SELF_CLOSED, B]),
    ("utf8-bom", b"\xef\xbb\xbf" + A, [A]),
    (
        "program-root",
        b"<CRCLProgram><InitCanon/></CRCLProgram>",
        [b"<CRCLProgram><InitCanon/></CRCLProgram>"],
    ),
    (
        "nested-same-name",
        b"<CRCLStatus><CRCLStatus/><a></a></CRCLStatus>",
        [b"<CRCLStatus><CRCLStatus/><a></a></CRCLStatus>"],
    ),
]


@pytest.mark.parametrize(
    ("stream", "documents"), [g[1:] for g in GOOD_STREAMS], ids=[g[0] for g in GOOD_STREAMS]
)
def test_streams_split_whole(stream: bytes, documents: list[bytes]) -> None:
    splitter = DocumentSplitter()
    assert splitter.feed(stream) == documents
    assert splitter.pending_bytes == 0 and splitter.started_at is None


@pytest.mark.parametrize(
    ("stream", "documents"), [g[1:] for g in GOOD_STREAMS], ids=[g[0] for g in GOOD_STREAMS]
)
def test_streams_split_byte_by_byte(stream: bytes, documents: list[bytes]) -> None:
    splitter = DocumentSplitter()
    got = [item for byte in stream for item in splitter.feed(bytes([byte]))]
    assert got == documents
    assert splitter.pending_bytes == 0


def test_split_documents_parse() -> None:
    out = DocumentSplitter().feed(A + B + C + TRICKY)
    assert [parse_command(doc).command_id for doc in out if isinstance(doc, bytes)] == [1, 2, 3, 4]


def errors(out: list[bytes | CrclFramingError]) -> list[tuple[bool, str]]:
    return [(item.recoverable, str(item)) for item in out if isinstance(item, CrclFramingError)]


BAD_STREAMS = [
    # (id, stream, what comes out: bytes, or (recoverable, words) for an error)
    (
        "text-between",
        A + b"joints 0 0 0\n" + B,
        [A, (True, "text outside a document: 'j"), B],
    ),
    ("text-first", b"hello" + A, [(True, "text outside a document: 'h"), A]),
    ("other-root", b"<Foo>x</Foo>" + A, [(True, "'<Foo>' does not start a CRCL document"), A]),
    ("end-tag-outside", b"</CRCLCommandInstance>" + A, [(True, "end tag outside a document"), A]),
    ("stray-lt", b"< " + A, [(True, "does not start a CRCL document"), A]),
    ("resync-skips-inner-tags", b"oops<CommandID>1</CommandID>" + B, [(True, "text outside"), B]),
    (
        "second-declaration",
        DECLARATION + DECLARATION + b"\n" + command(1),
        [(True, "second <?xml?> declaration"), DECLARATION + b"\n" + command(1)],
    ),
    (
        "doctype",
        b"<!DOCTYPE CRCLCommandInstance>" + A,
        [(False, "markup declaration '<!D")],
    ),
    (
        "doctype-after-declaration",
        DECLARATION + b"<!DOCTYPE x [<!ENTITY e 'e'>]>" + A,
        [(False, "refused")],
    ),
    ("entity-inside", b"<CRCLStatus><!ENTITY e 'x'></CRCLStatus>" + A, [(False, "refused")]),
    ("binary", A + b"\x01\x02" + B, [A, (False, f"binary data (byte 0x01 at offset {len(A)})")]),
]


@pytest.mark.parametrize(
    ("stream", "expected"), [b[1:] for b in BAD_STREAMS], ids=[b[0] for b in BAD_STREAMS]
)
def test_bad_streams(stream: bytes, expected: list[object]) -> None:
    for chunking in ("whole", "bytes"):
        splitter = DocumentSplitter()
        if chunking == "whole":
            out = splitter.feed(stream)
        else:
            out = [item for byte in stream for item in splitter.feed(bytes([byte]))]
        assert len(out) == len(expected), (chunking, out)
        for item, want in zip(out, expected):
            if isinstance(want, bytes):
                assert item == want, chunking
            else:
                assert isinstance(item, CrclFramingError), (chunking, item)
                recoverable, words = cast(tuple[bool, str], want)
                assert item.recoverable is recoverable and words in str(item), (chunking, item)
                assert item.command_id is None
        closing = [e for e in errors(out) if not e[0]]
        assert splitter.closed is bool(closing)
        if closing:
            assert "closing the stream" in closing[0][1]
            assert splitter.feed(A) == []


def test_half_sent_document_is_pending_with_its_start_time() -> None:
    splitter = DocumentSplitter()
    assert splitter.feed(A[:30], now=10.0) == []
    assert (splitter.pending_bytes, splitter.started_at) == (30, 10.0)
    assert splitter.feed(A[30:60], now=11.0) == []
    assert (splitter.pending_bytes, splitter.started_at) == (60, 10.0)
    assert splitter.feed(A[60:] + B[:5], now=12.0) == [A]
    assert (splitter.pending_bytes, splitter.started_at) == (5, 12.0)
    assert splitter.feed(B[5:], now=13.0) == [B]
    assert (splitter.pending_bytes, splitter.started_at) == (0, None)


def test_whitespace_and_finished_comments_are_not_pending() -> None:
    splitter = DocumentSplitter()
    assert splitter.feed(b"\n  <!-- idle -->\r\n", now=1.0) == []
    assert (splitter.pending_bytes, splitter.started_at) == (0, None)


def test_discard_pending_skips_the_rest_of_a_stalled_document() -> None:
    splitter = DocumentSplitter()
    splitter.feed(A[:80], now=1.0)
    assert splitter.discard_pending() == 80
    assert (splitter.pending_bytes, splitter.started_at) == (0, None)
    assert splitter.feed(A[80:] + B) == [B]  # the stale tail is skipped without an error


@st.composite
def streams(draw: st.DrawFn) -> tuple[list[bytes], bytes, list[int]]:
    """Documents with random filler between them, and random cut points."""
    pool = [A, B, C, TRICKY, SELF_CLOSED, command(7, "EndCanonType", "ns0")]
    documents = draw(st.lists(st.sampled_from(pool), min_size=1, max_size=6))
    filler = st.sampled_from([b"", b"\n", b" \r\n\t", b"<!-- c -->", b"<?pi?>\n"])
    stream = b"".join(draw(filler) + doc for doc in documents) + draw(filler)
    cuts = sorted(draw(st.lists(st.integers(0, len(stream)), max_size=12)))
    return documents, stream, cuts


@settings(max_examples=examples(200), deadline=None)
@given(streams())
def test_any_chunking_gives_the_same_documents(case: tuple[list[bytes], bytes, list[int]]) -> None:
    documents, stream, cuts = case
    splitter = DocumentSplitter()
    bounds = [0, *cuts, len(stream)]
    got = [item for a, b in zip(bounds, bounds[1:]) for item in splitter.feed(stream[a:b])]
    assert got == documents
    assert splitter.pending_bytes == 0


@settings(max_examples=examples(100), deadline=None)
@given(st.binary(max_size=300), st.integers(1, 50))
def test_any_bytes_any_chunking_never_crash_and_stay_bounded(data: bytes, size: int) -> None:
    splitter = DocumentSplitter(max_bytes=200)
    whole = DocumentSplitter(max_bytes=200).feed(data)
    got = []
    for i in range(0, len(data), size):
        got += splitter.feed(data[i : i + size])
        assert splitter.pending_bytes <= 200 + size
    assert [isinstance(item, bytes) for item in got] == [isinstance(item, bytes) for item in whole]
    assert [item for item in got if isinstance(item, bytes)] == [
        item for item in whole if isinstance(item, bytes)
    ]


FRAGMENTS = [b"<", b">", b"/", b"!--", b"-->", b"<?xml ", b"?>", b"<![CDATA[", b"]]>", b'"', b"'",
             b"<CRCLStatus", b"</CRCLStatus>", b"<p:CRCLProgram", b"</p:CRCLProgram >", b"a", b" ",
             b"\n", b"<!DOCTYPE", b"\xef\xbb", b"\xbf", b"<x>", b"</x>", b"/>"]  # fmt: skip


@settings(max_examples=examples(300), deadline=None)
@given(st.lists(st.sampled_from(FRAGMENTS), max_size=40), st.lists(st.integers(0, 200), max_size=8))
def test_markup_soup_splits_the_same_in_any_chunks(pieces: list[bytes], cuts: list[int]) -> None:
    """Documents, errors and what is left pending do not depend on how bytes arrive."""
    stream = b"".join(pieces)
    whole_splitter = DocumentSplitter()
    whole = whole_splitter.feed(stream)
    splitter = DocumentSplitter()
    bounds = [0, *sorted(min(cut, len(stream)) for cut in cuts), len(stream)]
    got = [item for a, b in zip(bounds, bounds[1:]) for item in splitter.feed(stream[a:b])]
    kinds = [item if isinstance(item, bytes) else item.recoverable for item in got]
    assert kinds == [item if isinstance(item, bytes) else item.recoverable for item in whole]
    assert all(item in stream for item in got if isinstance(item, bytes))
    assert splitter.pending_bytes == whole_splitter.pending_bytes
