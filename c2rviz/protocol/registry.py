"""The verb registry: every command of the language is one entry here.

A verb is declared once, on the frozen dataclass its parser returns::

    @verb("move", "i[,j,...] vi[,vj,...]", "set the listed joints; ...",
          examples=("move 0 1", "move 0,1 90,-90"))
    @dataclass(frozen=True, slots=True)
    class Move:
        indices: tuple[int, ...]
        values: tuple[float, ...]

        @staticmethod
        def parse(verb: str, words: list[str]) -> Move: ...

and handled once, by a function on the session side::

    @handler(Move)
    def move(session: Session, command: Move) -> Reply: ...

``help``, the command table (docs/commands.md), the parser tests (each verb's
``examples`` must parse to its class) and the clients' ``robot.VERB(*words)`` are all
made from ``VERBS``: a new verb is its entry, its handler and its row of the table.
This module has no I/O and imports nothing heavy: the clients use it (through
``protocol.parse_line``) without loading Pinocchio.
"""

from __future__ import annotations

from collections.abc import Awaitable, Callable
from dataclasses import dataclass
from typing import Any, TypeVar

Reply = str | Awaitable[str]
"""What a handler returns: the reply line now, or an awaitable of it (the reply waits,
and so do the connection's later lines; other connections go on)."""

Handler = Callable[[Any, Any], Reply]
"""``handler(session, command) -> Reply``; raises a ``C2rvizError`` to refuse."""


@dataclass(frozen=True, slots=True)
class Verb:
    """One verb of the command language.

    Attributes:
        name: The verb as ``help`` lists it.
        args: Its argument pattern (``""`` for none).
        summary: What it does, for the command table.
        command: The frozen dataclass the parser returns.
        parse: ``parse(verb, words) -> command``; raises ``BadArguments``.
        aliases: Other spellings of the verb.
        page: The docs page that tells of it (``help VERB`` names it), from the
            project's root.
        examples: Lines that use it, each one that parses to ``command``
            (``help VERB`` shows them; ``tests/protocol/test_registry.py`` parses them
            and asks every verb for one).
    """

    name: str
    args: str
    summary: str
    command: type
    parse: Callable[[str, list[str]], Any]
    aliases: tuple[str, ...] = ()
    page: str = "docs/commands.md"
    examples: tuple[str, ...] = ()

    @property
    def usage(self) -> str:
        return f"{self.name} {self.args}" if self.args else self.name


VERBS: dict[str, Verb] = {}
"""Every verb by name, in the order ``help`` lists them."""
LOOKUP: dict[str, Verb] = {}
"""Every verb by name and by alias (lower case)."""
HANDLERS: dict[type, Handler] = {}
"""The handler of each command class."""

C = TypeVar("C", bound=type)
F = TypeVar("F", bound=Handler)


def verb(
    name: str,
    args: str,
    summary: str,
    *,
    aliases: tuple[str, ...] = (),
    parse: Callable[[str, list[str]], Any] | None = None,
    page: str = "docs/commands.md",
    examples: tuple[str, ...] = (),
) -> Callable[[C], C]:
    """Register the decorated command class as verb ``name`` (stackable).

    ``parse`` defaults to the class's own ``parse``; a class with no fields and
    no ``parse`` takes no arguments. ``page`` is the docs page that tells of the verb
    (docs/commands.md, which lists every verb, unless a page of its own does).
    ``examples`` are lines of the verb, as a user types them: ``help VERB`` shows
    them, and the registry test parses each and wants at least one per verb.
    """

    def register(cls: C) -> C:
        chosen = parse or getattr(cls, "parse", None) or _no_args(cls)
        entry = Verb(name, args, summary, cls, chosen, aliases, page, examples)
        for word in (name, *aliases):
            if word in LOOKUP:
                raise ValueError(f"verb {word!r} is registered twice")
            LOOKUP[word] = entry
        VERBS[name] = entry
        return cls

    return register


def handler(command: type) -> Callable[[F], F]:
    """Register the decorated function as the handler of ``command``."""

    def register(fn: F) -> F:
        if command in HANDLERS:
            raise ValueError(f"{command.__name__} has two handlers")
        HANDLERS[command] = fn
        return fn

    return register


def usage(name: str) -> str:
    """The usage text of verb ``name`` (or of the verb it is an alias of)."""
    return LOOKUP[name].usage


def usages() -> dict[str, str]:
    """The usage of every verb and alias (the REPL completes these)."""
    return {word: v.usage for word, v in LOOKUP.items()}


def help_text() -> str:
    """The ``help`` reply's list: every verb (``|`` its aliases) and its arguments."""
    return "; ".join(
        "|".join((v.name, *v.aliases)) + (f" {v.args}" if v.args else "") for v in VERBS.values()
    )


def readme_table() -> str:
    """The command table of docs/commands.md, one row per verb (a test keeps them equal)."""
    rows = ["| command | meaning |", "|---|---|"]
    for v in VERBS.values():
        spelled = " / ".join(f"`{word}`" for word in v.aliases)
        usage = v.usage.replace("|", "\\|")
        rows.append(f"| `{usage}`{' / ' + spelled if spelled else ''} | {v.summary} |")
    return "\n".join(rows)


def _no_args(cls: type) -> Callable[[str, list[str]], Any]:
    instance = cls()

    def parse(verb: str, words: list[str]) -> Any:
        if words:
            from ..errors import BadArguments

            raise BadArguments(verb, "takes no arguments", usage(verb))
        return instance

    return parse
