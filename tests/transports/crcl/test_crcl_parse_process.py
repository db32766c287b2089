"""Issue 35, stall 4: a document over ``PARSE_ON_LOOP_BYTES`` is parsed in the door's
parsing process (``transports.parse_process``). It gives the statuses a small one gives,
the other clients go on while it parses, and a parsing process that dies costs that
document an error status; the next document starts a new process."""

from __future__ import annotations

import os
import signal
import time
from collections.abc import Callable, Iterator

import pytest
from crcl_support import DONE, ERROR, CrclServerThread, command, move_to
from support import Client, load_robot

from c2rviz.session import ServerLimits
from c2rviz.transports.crcl.server import PARSE_ON_LOOP_BYTES
from c2rviz.transports.parse_process import ParseProcess

INIT = command("InitCanon", 1)
WAIT_S = 60.0
pytestmark = pytest.mark.skipif(not hasattr(signal, "SIGSTOP"), reason="POSIX signals")


def padded(doc: bytes) -> bytes:
    """``doc`` with whitespace before its end tag: the same document, past the limit."""
    end = b"</CRCLCommandInstance>"
    return doc.replace(end, b" " * (2 * PARSE_ON_LOOP_BYTES) + end)


def message(command_id: int, text: str = "still here") -> bytes:
    return command("Message", command_id, f"<Message>{text}</Message>")


def until(condition: Callable[[], object]) -> None:
    """Wait for ``condition`` (a state of the server's own thread) to come true."""
    deadline = time.monotonic() + WAIT_S
    while not condition():
        assert time.monotonic() < deadline, "the condition never came true"
        time.sleep(0.01)


def parsing(server: object) -> ParseProcess:
    process = server.crcl._parsing  # type: ignore[attr-defined]
    assert isinstance(process, ParseProcess)
    return process


@pytest.fixture(scope="module")
def one_server() -> Iterator[CrclServerThread]:
    """One server for the four large documents below: none ends its parsing process, so
    one process parses them all (its start, about 0.6 s of CPU, is paid once)."""
    server = CrclServerThread(load_robot(), ServerLimits()).start()
    yield server
    server.stop()


@pytest.mark.parametrize(
    ("doc", "state", "words"),
    [
        (move_to(2, (0.5, 0.0, 0.8)), DONE, ""),
        (move_to(2, (0.5, 0.0, 0.8), x_axis=(1e300, 0, 0)), ERROR, "XAxis/I: 1e+300 is out of"),
        (command("MoveTo", 2, "<MoveStraight>maybe</MoveStraight>"), ERROR, "MoveStraight"),
        (command("NoSuch", 2), ERROR, "NoSuchType"),
    ],
    ids=["move", "huge-axis", "bad-boolean", "unknown-type"],
)
def test_a_large_document_gets_the_statuses_of_a_small_one(
    one_server, crcl_connect, doc: bytes, state: str, words: str
) -> None:
    small, large = crcl_connect(one_server), crcl_connect(one_server)
    assert len(padded(doc)) > PARSE_ON_LOOP_BYTES >= len(doc)
    for client, sent in ((small, doc), (large, padded(doc))):
        assert client.run(INIT, 1).command_status.state == DONE
        client.send(sent)
    said = small.until(2).command_status
    heard = large.until(2).command_status
    assert (heard.state, heard.description) == (said.state, said.description)
    assert said.state == state and words in (said.description or ""), said.description
    assert parsing(one_server).started == 1  # (the same process as for the others)


def test_others_go_on_while_a_large_document_parses(crcl_server, crcl_connect) -> None:
    """The parsing process is stopped (SIGSTOP) while it holds a large document: the
    text port and another CRCL client are answered meanwhile; the large document's
    client keeps its order once it goes on."""
    big, other = crcl_connect(crcl_server), crcl_connect(crcl_server)
    assert big.run(INIT, 1).command_status.state == DONE
    assert big.run(padded(message(2)), 2).command_status.state == DONE  # (its process starts)
    process = parsing(crcl_server)
    assert process.pid is not None
    os.kill(process.pid, signal.SIGSTOP)
    bystander = Client(crcl_server.host, crcl_server.port, timeout=WAIT_S)
    try:
        big.send(padded(message(3)) + message(4))
        until(lambda: process.busy)
        assert bystander.ask("where").startswith("ok ")
        assert other.run(INIT, 1).command_status.state == DONE
        assert process.busy and big.states(4) == []
    finally:
        os.kill(process.pid, signal.SIGCONT)
        bystander.close()
    assert big.until(3).command_status.state == DONE
    assert big.until(4).command_status.state == DONE
    assert big.states(3) == [DONE] and big.states(4) == [DONE]


def test_a_parsing_process_that_dies_costs_one_document(crcl_server, crcl_connect) -> None:
    """Killed while it parses, the process costs that document an error status that
    says so (CommandID 0: nothing of it was read); the connection goes on, and the next
    large document starts a new process."""
    client = crcl_connect(crcl_server)
    assert client.run(INIT, 1).command_status.state == DONE
    assert client.run(padded(message(2)), 2).command_status.state == DONE
    process = parsing(crcl_server)
    first = process.pid
    assert first is not None
    os.kill(first, signal.SIGSTOP)
    client.send(padded(message(3)))
    until(lambda: process.busy)
    os.kill(first, signal.SIGKILL)
    lost = client.status().command_status  # (its CommandID unread: 0)
    assert lost.state == ERROR and lost.command_id == 0, lost.description
    assert "the CRCL parsing process ended without an answer" in lost.description
    assert lost.description.endswith("the document was not read")
    assert client.run(padded(message(4)), 4).command_status.state == DONE
    assert client.run(message(5), 5).command_status.state == DONE
    assert process.started == 2 and process.pid not in (None, first)
