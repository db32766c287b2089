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


def test_the_parser_tables_cover_every_verb():
    tested = {line.split()[0].lower() for line, command, _ in GOOD if command is not None}
    missing = {v.name for v in VERBS.values()} - tested
    assert not missing, f"tests/test_parser.py GOOD has no line for {sorted(missing)}"
    for line, command, _ in GOOD:
        if command is not None:
            assert LOOKUP[line.split()[0].lower()].command is type(parse_line(line))


def test_help_lists_every_verb_and_alias_once():
    listed = [item.split()[0] for item in help_text().split("; ")]
    assert [w.split("|")[0] for w in listed] == list(VERBS)
    words = [word for item in listed for word in item.split("|")]
    assert sorted(words) == sorted(LOOKUP)
    assert "ok commands: " + help_text() == replies.help_reply()


def test_the_readme_command_table_is_the_registry():
    text = COMMANDS_DOC.read_text()
    found = re.search(r"<!-- commands:[^\n]*-->\n(.*?)\n<!-- /commands -->", text, re.S)
    assert found, "docs/commands.md lost its <!-- commands --> markers"
    assert found.group(1) == readme_table(), (
        "docs/commands.md's command table differs from the registry; paste this:\n" + readme_table()
    )
