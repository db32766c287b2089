"""Issue 39's faults at the CRCL door (2, 3, 4): each a CRCL_Error status that names what
was wrong, and the connection goes on."""

from __future__ import annotations

import logging
import select

import pytest
from crcl_support import DONE, ERROR, command, move_to
from hypothesis import given, settings
from hypothesis import strategies as st
from support import examples

INIT = command("InitCanon", 1)
STILL_HERE = command("Message", 3, "<Message>still here</Message>")


@pytest.mark.parametrize(
    ("axes", "words"),
    [
        ({"x_axis": (1e300, 0, 0)}, "EndPosition/XAxis/I: 1e+300 is out of range"),
        ({"z_axis": (0, 0, -1e300)}, "EndPosition/ZAxis/K: -1e+300 is out of range"),
        ({"x_axis": (1e300, 1e300, 1e300)}, "EndPosition/XAxis/I: 1e+300 is out of range"),
    ],
    ids=["x-axis-i", "z-axis-k", "x-axis-all"],
)
def test_a_huge_axis_component_is_an_error_and_the_next_document_runs(
    crcl_server, crcl_connect, axes: dict, words: str
) -> None:
    """39.2: it raised OverflowError, closed the connection and lost the next document."""
    client = crcl_connect(crcl_server)
    assert client.run(INIT, 1).command_status.state == DONE
    client.send(move_to(2, (0.5, 0.0, 0.8), **axes) + STILL_HERE)  # one write
    refused = client.until(2).command_status
    assert refused.state == ERROR and words in refused.description, refused.description
    assert client.until(3).command_status.state == DONE
    assert crcl_server.q == (0.0,) * 7


def test_a_bug_reading_a_document_costs_that_document_only(
    crcl_server, crcl_connect, monkeypatch
) -> None:
    """Whatever a document raises, the client hears an error and the connection goes on
    (an unexpected exception used to end it with no status: "Unhandled exception in
    client_connected_cb")."""
    from c2rviz.transports.crcl import commands
    from c2rviz.transports.crcl.server import INTERNAL_ERROR

    def boom(self: object) -> None:
        raise ArithmeticError("a bug")

    client = crcl_connect(crcl_server)
    assert client.run(INIT, 1).command_status.state == DONE
    monkeypatch.setattr(commands.MoveTo, "_check", boom)
    client.send(move_to(2, (0.5, 0.0, 0.8)))
    refused = client.status().command_status
    assert refused.state == ERROR and refused.description == INTERNAL_ERROR
    monkeypatch.undo()
    assert client.run(STILL_HERE, 3).command_status.state == DONE


def test_play_check_refuses_a_huge_axis_in_one_line(tmp_path, capsys) -> None:
    """39.2 in a program: ``c2rviz-play --check`` printed a traceback and exited 1."""
    from c2rviz.clients import player

    program = tmp_path / "huge.xml"
    program.write_text(
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        '<CRCLProgram xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance">\n'
        "  <InitCanon><CommandID>1</CommandID></InitCanon>\n"
        '  <MiddleCommand xsi:type="MoveToType"><CommandID>2</CommandID>\n'
        "    <MoveStraight>false</MoveStraight>\n"
        "    <EndPosition><Point><X>0.5</X><Y>0</Y><Z>0.8</Z></Point>\n"
        "      <XAxis><I>1</I><J>0</J><K>0</K></XAxis>\n"
        "      <ZAxis><I>0</I><J>0</J><K>-1e300</K></ZAxis></EndPosition>\n"
        "  </MiddleCommand>\n"
        "  <EndCanon><CommandID>3</CommandID></EndCanon>\n"
        "</CRCLProgram>\n"
    )
    assert player.main([str(program), "--check"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "EndPosition/ZAxis/K: -1e+300 is out of range" in err


@pytest.mark.parametrize(
    ("units", "point", "words"),
    [
        ("meter", (1e308, 0.0, 0.8), "EndPosition/Point/X: 1e+308 is out of range"),
        ("meter", (0.5, -1e308, 0.8), "EndPosition/Point/Y: -1e+308 is out of range"),
        ("millimeter", (500.0, 0.0, 2e6), "EndPosition/Point/Z: 2000000.0 is out of range"),
        ("meter", (2000.0, 0.0, 0.8), "Point/X: 2000 meter is out of range"),
        ("inch", (0.0, 50000.0, 0.8), "Point/Y: 50000 inch is out of range"),
    ],
    ids=["1e308-m", "-1e308-m", "2e6-mm", "2000-m", "50000-inch"],
)
def test_a_position_past_1000_m_is_refused_with_the_text_ports_range(
    crcl_server, crcl_connect, units: str, point: tuple, words: str
) -> None:
    """39.3: 1e308 was accepted, then refused as "target is inf m" (numpy's overflow
    warning besides); the range is the text port's, ±1000 m."""
    client = crcl_connect(crcl_server)
    assert client.run(INIT, 1).command_status.state == DONE
    unit = f"<UnitName>{units}</UnitName>"
    assert client.run(command("SetLengthUnits", 2, unit), 2).command_status.state == DONE
    client.send(move_to(4, point) + STILL_HERE)
    refused = client.until(4).command_status
    assert refused.state == ERROR and words in refused.description, refused.description
    assert "-1000..1000 m" in refused.description or "1000 m of the origin" in refused.description
    assert "inf" not in refused.description
    assert client.until(3).command_status.state == DONE
    assert crcl_server.q == (0.0,) * 7


def test_the_stall_clock_runs_from_a_documents_first_byte(start_crcl, crcl_connect) -> None:
    """39.4: each read restarted the clock, so a byte every 6 s kept a document half-sent
    for 36 s (and would forever). Here a byte comes every half timeout: the document is
    dropped all the same, long before the trickle ends."""
    server = start_crcl(stall_timeout_s=0.6)
    client = crcl_connect(server)
    doc = command("InitCanon", 1)
    client.send(doc[:20])
    stalled = None
    for byte in doc[20:60]:  # 40 bytes, one each 0.3 s: 12 s, twenty timeouts
        readable, _, _ = select.select([client.sock], [], [], 0.3)
        if readable:
            stalled = client.status().command_status
            break
        client.send(bytes([byte]))
    assert stalled is not None, "a document trickled byte by byte was never dropped"
    assert stalled.state == ERROR and "stalled for 0.6 s: dropped" in stalled.description
    assert client.run(doc, 1).command_status.state == DONE


def test_refused_connections_are_logged_as_a_count(start_crcl, crcl_connect, caplog) -> None:
    """39.4: each refused connection logged a warning line (184 for 200 connections)."""
    server = start_crcl(max_connections=1)
    served = crcl_connect(server)
    assert served.run(INIT, 1).command_status.state == DONE
    with caplog.at_level(logging.WARNING, logger="c2rviz.crcl"):
        for _ in range(30):
            refused = crcl_connect(server)
            assert "too many CRCL connections" in refused.status().command_status.description
            assert refused.closed_by_server()
        server.call_async(server.crcl.stop())  # the count so far is logged as it stops
    lines = [r.getMessage() for r in caplog.records if "refused" in r.getMessage()]
    assert len(lines) == 2, lines
    assert lines[0].startswith("refused CRCL client 127.0.0.1:")
    assert lines[1].startswith("refused 29 more CRCL clients (too many connections)")
    assert server.crcl.refused == 30


_PIECES = st.sampled_from(
    [
        "<a>", "</a>", "<b/>", "<c x='1'>", '<d y="a>b"/>', "</c>", "text", " a > b ",
        "a/>b", "< 1", "<!-- </CRCLCommandInstance> -->", "<![CDATA[</x>]]>", "<?pi ?>",
        "<CRCLCommandInstance>", "</CRCLCommandInstance>", "<p:q>", "</p:q>", "<e\n/>",
        "</e >", "<<f>", "it's",
    ]
)  # fmt: skip


@settings(max_examples=examples(300), deadline=None)
@given(
    body=st.lists(_PIECES, max_size=40),
    cuts=st.lists(st.integers(1, 50), min_size=1, max_size=8),
)
def test_the_plain_skim_cuts_as_the_tag_by_tag_skim(body: list[str], cuts: list[int]) -> None:
    """Issue 35, stall 4: the splitter steps over plain tags in C now (``_skim_plain``);
    whatever the bytes and however they are cut, it gives what the tag-by-tag skim gave."""
    from c2rviz.transports.crcl.framing import DocumentSplitter

    data = ("<CRCLCommandInstance>" + "".join(body) + "</CRCLCommandInstance> <x/>").encode()
    data = data * 2

    def split(plain: bool) -> list[object]:
        splitter = DocumentSplitter(max_bytes=4096)
        if not plain:
            splitter._skim_plain = lambda out: False  # type: ignore[method-assign]
        out: list[object] = []
        start, turn = 0, 0
        while start < len(data):
            size = cuts[turn % len(cuts)]
            out += [
                x if isinstance(x, bytes) else str(x)
                for x in splitter.feed(data[start : start + size])
            ]
            start, turn = start + size, turn + 1
        return [*out, splitter.pending_bytes]

    assert split(plain=True) == split(plain=False)
