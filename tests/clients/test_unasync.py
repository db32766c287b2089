"""The clients are written once: ``Client``'s verbs are generated from ``AsyncClient``'s
(``scripts/unasync_clients.py``), and a verb of the registry with no typed method yet is
still a method of both clients."""

from __future__ import annotations

import asyncio
import importlib.util
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest

from c2rviz import AsyncClient, Client, CommandError
from c2rviz.errors import BadArguments
from c2rviz.protocol.registry import HANDLERS, LOOKUP, VERBS, handler, verb

SCRIPT = Path(__file__).resolve().parents[2] / "scripts" / "unasync_clients.py"


def load_script():
    spec = importlib.util.spec_from_file_location("unasync_clients", SCRIPT)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_blocking_verbs_are_the_async_ones_unasynced():
    """Edit ``aio_verbs.py``/``aio_scene_verbs.py``, then run the script: else this fails."""
    script = load_script()
    for path, text in script.generated().items():
        assert path.read_text() == text, f"{path.name} is stale: run python {SCRIPT.name}"
    assert script.main(["--check"]) == 0


def test_unasync_drops_async_and_renames():
    script = load_script()
    source = '"""doc."""\nclass AsyncVerbs:\n    async def f(self):\n        await self.g()\n'
    text = script.unasync(source, "aio_verbs.py", "new doc.")
    body = text[text.index("class") :]
    assert "async" not in body and "await" not in body
    assert "class Verbs:" in text and "def f(self):" in text and "self.g()" in text
    assert '"""new doc."""' in text and '"""doc."""' not in text


@dataclass(frozen=True, slots=True)
class Echo:
    """A verb that exists only in this test."""

    words: tuple[str, ...]

    @staticmethod
    def parse(verb: str, words: list[str]) -> Echo:
        return Echo(tuple(words))


def echo(session: object, command: Echo) -> str:
    if command.words == ("no",):
        raise BadArguments("echo", "refused", "echo WORD...")
    return "ok " + " ".join(command.words)


@pytest.fixture
def new_verb() -> Iterator[None]:
    """A new verb as a contributor adds one: its protocol entry and its handler, nothing
    in the clients."""
    verb("echo", "WORD...", "reply the words")(Echo)
    handler(Echo)(echo)
    try:
        yield
    finally:
        VERBS.pop("echo")
        LOOKUP.pop("echo")
        HANDLERS.pop(Echo)


def test_a_new_verb_is_a_method_of_both_clients(new_verb, server):
    with Client(server.host, server.port) as robot:
        assert robot.echo("a", 1.5) == "ok a 1.5"
    with Client(server.host, server.port) as robot:
        assert robot.send("echo b") == "ok b"

    async def main() -> None:
        async with AsyncClient(server.host, server.port) as robot:
            assert await robot.echo("c", 2) == "ok c 2"

    asyncio.run(main())


def test_a_name_that_is_no_verb_is_no_method(server):
    robot = Client(server.host, server.port)
    with pytest.raises(AttributeError, match="'Client' object has no attribute 'echo'"):
        robot.echo  # noqa: B018
    with pytest.raises(AttributeError, match="_private"):
        robot._private  # noqa: B018
    assert not hasattr(AsyncClient(), "frobnicate")


def test_a_generic_verb_raises_for_an_error_reply(new_verb, server):
    with Client(server.host, server.port) as robot:
        with pytest.raises(CommandError, match="echo: refused"):
            robot.echo("no")
        assert robot.echo("yes") == "ok yes"  # the connection goes on
