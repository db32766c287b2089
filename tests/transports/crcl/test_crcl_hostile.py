"""Hostile documents: external entities, entity expansion, DOCTYPEs, size, bytes.

The secret of the XXE test lives in a real file; whatever the parser does, its text
must appear nowhere: not in a result, not in an error message.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from lxml import etree

from c2rviz.transports.crcl import (
    MAX_DOCUMENT_BYTES,
    CrclError,
    CrclFramingError,
    CrclSyntaxError,
    CrclValueError,
    DocumentSplitter,
    Message,
    parse_command,
    parse_program,
    parse_status,
    write_command,
)
from c2rviz.transports.crcl.documents import _parser

SECRET = "c2rviz-secret-7f3a9b"
XSI = 'xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"'


def message_doc(text: str, doctype: str = "") -> bytes:
    return (
        f'<?xml version="1.0" encoding="UTF-8"?>\n{doctype}'
        f'<CRCLCommandInstance {XSI}><CRCLCommand xsi:type="MessageType">'
        f"<CommandID>1</CommandID><Message>{text}</Message></CRCLCommand>"
        f"</CRCLCommandInstance>"
    ).encode()


@pytest.fixture
def secret_file(tmp_path: Path) -> Path:
    path = tmp_path / "secret.txt"
    path.write_text(SECRET)
    return path


def hostile_documents(secret: Path) -> dict[str, bytes]:
    laughs = '<!ENTITY lol0 "lol">' + "".join(
        f'<!ENTITY lol{n} "{f"&lol{n - 1};" * 10}">' for n in range(1, 10)
    )
    return {
        "xxe-file": message_doc(
            "&xxe;", f'<!DOCTYPE CRCLCommandInstance [<!ENTITY xxe SYSTEM "file://{secret}">]>'
        ),
        "xxe-parameter": message_doc(
            "x",
            f'<!DOCTYPE CRCLCommandInstance [<!ENTITY % p SYSTEM "file://{secret}"> %p;]>',
        ),
        "billion-laughs": message_doc("&lol9;", f"<!DOCTYPE CRCLCommandInstance [{laughs}]>"),
        "doctype-plain": message_doc("x", "<!DOCTYPE CRCLCommandInstance>"),
        "doctype-lower": message_doc("x", "<!doctype CRCLCommandInstance>"),
        "doctype-external-dtd": message_doc(
            "x", f'<!DOCTYPE CRCLCommandInstance SYSTEM "file://{secret}">'
        ),
        "entity-without-doctype": message_doc("&xxe;", f'<!ENTITY xxe SYSTEM "file://{secret}">'),
        "xinclude": message_doc(
            f'<xi:include xmlns:xi="http://www.w3.org/2001/XInclude" href="file://{secret}"'
            ' parse="text"/>'
        ),
    }


NAMES = [
    "xxe-file",
    "xxe-parameter",
    "billion-laughs",
    "doctype-plain",
    "doctype-lower",
    "doctype-external-dtd",
    "entity-without-doctype",
    "xinclude",
]


@pytest.mark.parametrize("name", NAMES)
def test_hostile_documents_are_refused_and_leak_nothing(name: str, secret_file: Path) -> None:
    doc = hostile_documents(secret_file)[name]
    refusal = CrclValueError if name == "xinclude" else CrclSyntaxError
    with pytest.raises(refusal) as caught:
        parse_command(doc)
    assert SECRET not in str(caught.value)
    if name == "xinclude":  # never processed: an element where text belongs
        assert "Message: must hold a xs:string value, not elements" in str(caught.value)
    else:
        assert caught.value.command_id is None
        assert "refused" in str(caught.value)


@pytest.mark.parametrize("name", NAMES[:3])
def test_lxml_settings_alone_do_not_expand(name: str, secret_file: Path) -> None:
    """Second line of defence: even past the byte scan, the parser expands nothing."""
    doc = hostile_documents(secret_file)[name]
    try:
        root = etree.fromstring(doc, _parser())
    except etree.XMLSyntaxError as error:
        assert SECRET not in str(error)
        return
    text = etree.tostring(root).decode()
    assert SECRET not in text
    assert "lollollol" not in text


@pytest.mark.parametrize("name", ["doctype-plain", "billion-laughs", "xxe-file"])
def test_program_and_status_parsers_refuse_too(name: str, secret_file: Path) -> None:
    doc = hostile_documents(secret_file)[name]
    for root in (b"CRCLProgram", b"CRCLStatus"):
        with pytest.raises(CrclSyntaxError, match="DOCTYPE|ENTITY"):
            (parse_program if root == b"CRCLProgram" else parse_status)(
                doc.replace(b"CRCLCommandInstance", root)
            )


def test_splitter_closes_on_a_doctype(secret_file: Path) -> None:
    splitter = DocumentSplitter()
    out = splitter.feed(hostile_documents(secret_file)["xxe-file"] + message_doc("after"))
    assert len(out) == 1 and isinstance(out[0], CrclFramingError)
    assert not out[0].recoverable
    assert "refused" in str(out[0]) and SECRET not in str(out[0])
    assert splitter.closed and splitter.feed(message_doc("more")) == []


def padded(size: int) -> bytes:
    """A valid Message document of exactly ``size`` bytes."""
    bare = message_doc("")
    return message_doc("x" * (size - len(bare)))


def test_size_limit_is_exact() -> None:
    assert len(padded(MAX_DOCUMENT_BYTES)) == MAX_DOCUMENT_BYTES
    command = parse_command(padded(MAX_DOCUMENT_BYTES))
    assert isinstance(command, Message)
    with pytest.raises(CrclSyntaxError, match=f"over the limit of {MAX_DOCUMENT_BYTES}"):
        parse_command(padded(MAX_DOCUMENT_BYTES + 1))


def test_splitter_size_limit_is_exact() -> None:
    splitter = DocumentSplitter()
    chunks = [
        padded(MAX_DOCUMENT_BYTES)[i : i + 65536] for i in range(0, MAX_DOCUMENT_BYTES, 65536)
    ]
    got = [item for chunk in chunks for item in splitter.feed(chunk)]
    assert got == [padded(MAX_DOCUMENT_BYTES)]
    over = padded(MAX_DOCUMENT_BYTES + 1)
    got = [item for i in range(0, len(over), 65536) for item in splitter.feed(over[i : i + 65536])]
    assert len(got) == 1 and not isinstance(got[0], bytes) and not got[0].recoverable
    assert "over the limit of 1048576" in str(got[0])


def test_splitter_refuses_an_endless_document_before_its_end() -> None:
    splitter = DocumentSplitter(max_bytes=4096)
    out = splitter.feed(message_doc("x" * 5000)[:4500])
    assert len(out) == 1 and "over the limit of 4096" in str(out[0])
    assert splitter.closed and splitter.pending_bytes == 0


@pytest.mark.parametrize(
    "data",
    [
        b"\x16\x03\x01\x02\x00\x01\x00\x01\xfc\x03\x03",  # a TLS ClientHello
        bytes(range(256)),
        message_doc("x")[:60] + b"\x00\xff\xfe" + message_doc("y"),
    ],
    ids=["tls-hello", "all-bytes", "nul-inside-a-document"],
)
def test_binary_garbage_closes_the_stream(data: bytes) -> None:
    splitter = DocumentSplitter()
    out = splitter.feed(data)
    last = out[-1]
    assert isinstance(last, CrclFramingError) and not last.recoverable
    assert "binary data" in str(last)
    assert splitter.closed


@pytest.mark.parametrize(
    "doc",
    [
        '<?xml version="1.0" encoding="UTF-16"?><CRCLCommandInstance/>'.encode("utf-16"),
        b'<?xml version="1.0" encoding="ISO-8859-1"?><CRCLCommandInstance/>',
        b"<CRCLCommandInstance>\x00</CRCLCommandInstance>",
        b"<CRCLCommandInstance>\xff\xfe</CRCLCommandInstance>",
    ],
    ids=["utf-16", "latin-1", "nul", "invalid-utf-8"],
)
def test_only_utf8_documents(doc: bytes) -> None:
    with pytest.raises(CrclSyntaxError, match="UTF-8|malformed"):
        parse_command(doc)


def test_a_message_that_looks_like_markup_is_just_text() -> None:
    command = Message(command_id=3, message="<!DOCTYPE x> &xxe; </CRCLCommandInstance>")
    doc = write_command(command)
    assert b"<!DOCTYPE" not in doc
    assert parse_command(doc) == command
    assert DocumentSplitter().feed(doc) == [doc]


@pytest.mark.parametrize(
    "doc",
    [
        message_doc("x").replace(b"MessageType", b"M" * 500_000),
        message_doc("x").replace(b"<Message>x</Message>", b"<" + b"W" * 500_000 + b"/>"),
        message_doc("x").replace(b"<Message>x</Message>", b"<a" + b"b" * 500_000 + b">"),
        b"<" + b"R" * 500_000 + b"/>",
        message_doc("x").replace(b"<Message>x", b"<Message>" + b"<a>" * 50_000 + b"</a>" * 50_000),
    ],
    ids=["long-xsi-type", "long-element-name", "long-malformed", "long-root", "deep-nesting"],
)
def test_huge_names_and_depths_give_short_messages(doc: bytes) -> None:
    with pytest.raises(CrclError) as caught:
        parse_command(doc)
    assert len(str(caught.value)) < 300
