"""Server text made safe to print: control characters shown escaped.

A reply is shown to a person by the REPL and the player; one that carries terminal
escape sequences (``\\x1b[2J``, a title change, bidirectional overrides) must not
act on their terminal. ``shown`` writes every character ``str.isprintable`` refuses
(C0/C1 controls, DEL, format characters such as U+202E, separators) as a Python
escape (``\\x1b``, ``\\u202e``); tabs and ordinary text pass as they are.
"""

from __future__ import annotations

__all__ = ["shown"]


def _escape(char: str) -> str:
    code = ord(char)
    if code < 0x100:
        return f"\\x{code:02x}"
    if code < 0x10000:
        return f"\\u{code:04x}"
    return f"\\U{code:08x}"


def shown(text: str) -> str:
    """``text`` with every control or format character written as its escape."""
    if text.isprintable():
        return text
    return "".join(char if char.isprintable() or char == "\t" else _escape(char) for char in text)
