"""The verb registry: one entry per verb, a handler for each, and the command table made from it."""

from __future__ import annotations

import re

from support import ROOT
from test_parser import GOOD

from c2rviz.protocol import replies
from c2rviz.protocol.grammar import parse_line
from c2rviz.protocol.registry import HANDLERS, LOOKUP, VERBS, help_text, readme_table

COMMANDS_DOC = ROOT / "docs" / "commands.md"


def test_every_verb_has_one_handler_and_parses_to_its_class():
    for verb in VERBS.values():
        assert verb.command in HANDLERS, f"{verb.name} has no @handler"
    assert set(HANDLERS) == {verb.command for verb in VERBS.values()}
    for word, verb in LOOKUP.items():
        assert word == word.lower() and " " not in word
        assert verb.name == word or word in verb.aliases


def test_every_verb_carries_examples_that_parse_to_its_class():
    """A verb's example lines live in its entry (``@verb(..., examples=...)``): at least
    one each, each a line of that verb (name or alias) that parses to its class
    (``test_parser.test_each_verbs_examples_parse`` runs them one by one too)."""
    for verb in VERBS.values():
        assert verb.examples, f"{verb.name} has no examples: @verb(..., examples=(LINE, ...))"
        for line in verb.examples:
            assert LOOKUP[line.split()[0].lower()] is verb, f"{line!r} is not a {verb.name} line"
            assert type(parse_line(line)) is verb.command, line


def test_the_parser_table_lines_parse_to_their_verbs_class():
    for line, command, _ in GOOD:
        if command is not None:
            assert LOOKUP[line.split()[0].lower()].command is type(parse_line(line))


def test_help_lists_every_verb_and_alias_once():
    listed = [item.split()[0] for item in help_text().split("; ")]
    assert [w.split("|")[0] for w in listed] == list(VERBS)
    words = [word for item in listed for word in item.split("|")]
    assert sorted(words) == sorted(LOOKUP)
    assert "ok commands: " + help_text() == replies.help_reply()


def test_help_verb_gives_its_line_and_a_docs_page_that_tells_of_it():
    lines = help_text().split("; ")
    for word, entry in LOOKUP.items():
        command = parse_line(f"help {word}")
        text = command.reply_text()
        line = next(item for item in lines if item.split()[0].split("|")[0] == entry.name)
        examples = ", ".join(f"`{example}`" for example in entry.examples)
        assert text.startswith(f"{line}: {entry.summary}; e.g. {examples}; see docs/"), text
        page = ROOT / text.rsplit("; see ", 1)[1]
        assert page.is_file(), page
        said = page.read_text()
        assert f"`{entry.name}" in said or f"> {entry.name}" in said, f"{page} lacks {word}"


def test_help_verb_through_a_server(server, connect):
    client = connect(server)
    assert client.ask("help") == replies.help_reply()  # alone: the list, as ever
    reply = client.ask("help moveto")
    assert reply.startswith("ok moveto x,y,z[,roll,pitch,yaw] | marker N: go to that tool pose")
    assert "; e.g. `moveto 0.5,0,0.8,0,90,0`, `moveto 0.5,0,0.8`, `moveto marker 3`; " in reply
    assert reply.endswith("; see docs/cartesian.md")
    assert client.ask("help movto") == (
        "error: help: no verb 'movto': did you mean 'moveto'? (usage: help [VERB])"
    )


def test_the_readme_command_table_is_the_registry():
    text = COMMANDS_DOC.read_text()
    found = re.search(r"<!-- commands:[^\n]*-->\n(.*?)\n<!-- /commands -->", text, re.S)
    assert found, "docs/commands.md lost its <!-- commands --> markers"
    assert found.group(1) == readme_table(), (
        "docs/commands.md's command table differs from the registry; paste this:\n" + readme_table()
    )
