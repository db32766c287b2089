"""Bad input at the CRCL door (issue 24): each gets a CRCL_Error status saying what was
wrong (and, where the stream cannot be re-synchronised, then the documented close);
the arm never moves partly; the text port and the other CRCL clients go on."""

from __future__ import annotations

import time

import pytest
from crcl_support import (
    DONE,
    ERROR,
    CrclClient,
    CrclServerThread,
    command,
    instance,
    move_to,
)
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from support import examples

REACH = (0.5, 0.0, 0.8)


def frames(server: CrclServerThread) -> int:
    return server.call(lambda: len(server.scene.joints))


def others_go_on(server: CrclServerThread, connect, crcl_connect) -> None:
    """The text port and a new CRCL client are served as before."""
    text = connect(server)
    assert text.ask("where").startswith("ok ")
    fresh: CrclClient = crcl_connect(server)
    assert fresh.run(command("InitCanon", 1), 1).command_status.state == DONE


MALFORMED = (
    b'<?xml version="1.0" encoding="UTF-8"?>\n<CRCLCommandInstance xmlns:xsi='
    b'"http://www.w3.org/2001/XMLSchema-instance">\n  <CRCLCommand xsi:type="InitCanonType">'
    b"<CommandID>1</CommandIDX></CRCLCommand>\n</CRCLCommandInstance>\n"
)


@pytest.mark.parametrize(
    ("doc", "command_id", "words"),
    [
        (MALFORMED, 0, "malformed XML"),
        (command("Fly", 4), 4, "unknown xsi:type 'FlyType'"),
        (instance("InitCanonType", "    <Name>no id</Name>"), 0, "CommandID"),
        (instance("InitCanonType", "<CommandID>abc</CommandID>"), 0, "CommandID"),
        (instance("InitCanonType", "<CommandID>-3</CommandID>"), 0, "CommandID"),
        (instance("InitCanonType", f"<CommandID>{2**70}</CommandID>"), 0, "CommandID"),
        (move_to(5, (9.25, 0.0, 0.8)).replace(b"9.25", b"NaN"), 5, "X: NaN is not allowed"),
        (move_to(6, (9.25, 0.0, 0.8)).replace(b"9.25", b"-INF"), 6, "X: -INF is not allowed"),
        (move_to(7, (9.25, 0.0, 0.8)).replace(b"9.25", b"1e999"), 7, "X: '1e999' is too large"),
        (command("SetEndEffector", 8, "<Setting>1.5</Setting>"), 8, "1.5"),
        (command("SetLengthUnits", 9, "<UnitName>furlong</UnitName>"), 9, "furlong"),
    ],
    ids=[
        "malformed",
        "unknown-type",
        "no-command-id",
        "command-id-not-integer",
        "command-id-negative",
        "command-id-huge",
        "nan",
        "inf",
        "overflow",
        "fraction-over-1",
        "unknown-unit",
    ],
)
def test_a_bad_document_is_an_error_and_the_connection_goes_on(
    crcl_server, crcl_connect, connect, doc: bytes, command_id: int, words: str
) -> None:
    client = crcl_connect(crcl_server)
    assert client.run(command("InitCanon", 1), 1).command_status.state == DONE
    before = frames(crcl_server)
    client.send(doc)
    refused = client.until(command_id, (ERROR,)).command_status
    assert words in refused.description, refused.description
    assert client.run(command("Message", 2, "<Message>still here</Message>"), 2)
    assert client.states(2) == [DONE]
    assert frames(crcl_server) == before and crcl_server.q == (0.0,) * 7
    others_go_on(crcl_server, connect, crcl_connect)


XXE = (
    b'<?xml version="1.0"?>\n<!DOCTYPE d [<!ENTITY x SYSTEM "file:///etc/passwd">]>\n'
    b'<CRCLCommandInstance xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance">'
    b'<CRCLCommand xsi:type="MessageType"><CommandID>1</CommandID><Message>&x;</Message>'
    b"</CRCLCommand></CRCLCommandInstance>"
)
LAUGHS = (
    b'<?xml version="1.0"?>\n<!DOCTYPE lolz [<!ENTITY lol "lol">'
    + b"".join(b'<!ENTITY lol%d "%s">' % (i, b"&lol%d;" % (i - 1) * 10) for i in range(1, 10))
    + b"]>\n<CRCLCommandInstance/>"
)


@pytest.mark.parametrize(
    ("data", "words"),
    [
        (XXE, "markup declaration '<!DOCTYPE d [<!EN"),
        (LAUGHS, "refused (no DOCTYPE)"),
        (b"\x00\x01\xfe\xffgarbage", "binary data (byte 0x00 at offset 0)"),
        (command("InitCanon", 1)[:-40] + b"\x07" + b"x" * 100, "binary data (byte 0x07"),
        (
            command("Message", 1, "<Message>" + "a" * 5000 + "</Message>"),
            "over the limit of 4096",
        ),
    ],
    ids=["xxe", "billion-laughs", "binary", "binary-inside", "over-the-size-limit"],
)
def test_what_cannot_be_resynchronised_is_an_error_then_the_close(
    start_crcl, crcl_connect, connect, data: bytes, words: str
) -> None:
    server = start_crcl(max_document_bytes=4096)
    client = crcl_connect(server)
    client.send(data)
    status = client.status().command_status
    assert (status.state, status.command_id) == (ERROR, 0)
    assert words in status.description and "closing the stream" in status.description
    assert client.closed_by_server()
    assert not any(b"root:" in raw for raw in client.raw)
    others_go_on(server, connect, crcl_connect)


def test_a_half_document_that_stalls_is_dropped_and_the_next_runs(start_crcl, crcl_connect) -> None:
    server = start_crcl(stall_timeout_s=0.3)
    client = crcl_connect(server)
    doc = command("InitCanon", 1)
    client.send(doc[:60])
    stalled = client.status().command_status
    assert stalled.state == ERROR and stalled.command_id == 0
    assert stalled.description.startswith("half a document (60 bytes) stalled for 0.3 s")
    assert client.run(doc, 1).command_status.state == DONE


def test_a_document_in_many_pieces_within_the_timeout_is_not_stalled(
    start_crcl, crcl_connect
) -> None:
    """The stall clock runs from the document's first byte: a document whose pieces all
    come within the timeout is run, however many they are."""
    server = start_crcl(stall_timeout_s=5.0)
    client = crcl_connect(server)
    doc = command("InitCanon", 1)
    pieces = [doc[i : i + 40] for i in range(0, len(doc), 40)]
    for piece in pieces:
        client.send(piece)
        time.sleep(0.05)
    assert client.run(b"", 1).command_status.state == DONE
    assert [s.command_status.state for s in client.seen] == [DONE]


@pytest.mark.parametrize(
    ("junk", "words"),
    [
        (b"joints 0,0,0,0,0,0,0\n", "text outside a document: 'joints 0,0,0,0,0,0,0"),
        (b"<Foo/>", "'<Foo/>' does not start a CRCL document"),
        (b"</CRCLCommandInstance>", "end tag outside a document"),
    ],
    ids=["a-text-line", "another-root", "a-stray-end-tag"],
)
def test_what_is_not_a_document_is_skipped_with_an_error(
    crcl_server, crcl_connect, junk: bytes, words: str
) -> None:
    client = crcl_connect(crcl_server)
    client.send(junk + command("InitCanon", 1))
    skipped = client.status().command_status
    assert skipped.state == ERROR and skipped.command_id == 0
    assert words in skipped.description and "skipping to the next document" in (skipped.description)
    assert client.until(1).command_status.state == DONE


def test_one_connection_over_the_cap_is_told_and_closed(start_crcl, crcl_connect, connect) -> None:
    server = start_crcl(max_connections=2)
    first, second = crcl_connect(server), crcl_connect(server)
    assert first.run(command("InitCanon", 1), 1).command_status.state == DONE
    assert second.run(command("InitCanon", 1), 1).command_status.state == DONE
    third = crcl_connect(server)
    refused = third.status().command_status
    assert refused.state == ERROR
    assert refused.description == "too many CRCL connections (limit 2); closing"
    assert third.closed_by_server()
    assert first.run(command("Message", 2, "<Message>on</Message>"), 2).command_status.state == DONE
    assert connect(server).ask("where").startswith("ok ")


def test_a_client_that_never_reads_is_reset_and_no_one_else_notices(
    start_crcl, crcl_connect, connect
) -> None:
    server = start_crcl(max_unread=65536)
    flooder = crcl_connect(server)
    sent = 0
    burst = command("GetStatus", 1) * 1000  # each answered with a full status (~2.5 kB)
    try:
        for _ in range(40):  # 100 MB of statuses: far more than the socket buffers hold
            flooder.send(burst)
            sent += 1000
    except (BrokenPipeError, ConnectionResetError):
        pass  # reset by the server while we sent
    others_go_on(server, connect, crcl_connect)
    answered = 0
    try:
        while chunk := flooder.sock.recv(1 << 20):
            answered += chunk.count(b"</CRCLStatus>")
    except ConnectionResetError:
        pass
    assert answered < sent  # cut off: the server dropped it rather than hold its statuses


@settings(
    max_examples=examples(25),
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture],
)
@given(junk=st.binary(min_size=1, max_size=300) | st.text(max_size=300).map(str.encode))
def test_junk_never_costs_the_server(crcl_server, connect, junk: bytes) -> None:
    client = CrclClient(crcl_server.host, crcl_server.crcl_port)
    try:
        client.send(junk + command("GetStatus", 1))
        client.sock.settimeout(60)
        try:
            while client.status():  # every status parses and keeps the rules
                if client.seen[-1].settings_status is not None:
                    break
        except (EOFError, ConnectionResetError):
            pass  # a stream that cannot be trusted was closed, after its error status
    finally:
        client.close()
    assert connect(crcl_server).ask("where").startswith("ok ")
    assert crcl_server.q == (0.0,) * 7
