"""What a client prints of the server's text: control characters shown escaped, and the
player's progress.

A reply is shown to a person by the REPL and the player; one that carries terminal
escape sequences (``\x1b[2J``, a title change, bidirectional overrides) must not
act on their terminal. ``shown`` writes every character ``str.isprintable`` refuses
(C0/C1 controls, DEL, format characters such as U+202E, separators) as a Python
escape (``\x1b``, ``\u202e``); tabs and ordinary text pass as they are.

``Progress`` is how ``c2rviz-play`` (and the REPL's ``file``) shows each played line
and its reply (the server's text escaped by ``shown``).
"""

from __future__ import annotations

import shutil
from typing import TextIO

__all__ = ["Progress", "shown"]


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


class Progress:
    """Shows each played line and its reply.

    On a terminal (``in_place``) one status line is rewritten in place; replies
    that carry data and every error stay on screen. Otherwise one plain line
    per command. ``quiet``: errors alone (``c2rviz-play --quiet``).
    """

    def __init__(
        self, out: TextIO, err: TextIO, in_place: bool | None = None, *, quiet: bool = False
    ) -> None:
        self.out = out
        self.err = err
        self.quiet = quiet
        self.in_place = out.isatty() if in_place is None else in_place
        self._dirty = False

    def step(self, label: str, text: str, reply: str) -> None:
        if self.quiet:
            return
        message = f"{label} {text} -> {shown(reply)}"
        if not self.in_place:
            print(message, file=self.out, flush=True)
            return
        keep = reply not in ("ok", "ok bye") and not reply.startswith("error")
        fitted = message if keep else self._fit(message)
        self.out.write("\r\x1b[K" + fitted + ("\n" if keep else ""))
        self.out.flush()
        self._dirty = not keep

    def waiting(self, label: str, text: str, note: str) -> None:
        """On a terminal, show that ``text``'s reply is awaited (``-> moving``); the
        ``step`` that follows overwrites it. Elsewhere nothing: one line per command."""
        if not self.in_place or self.quiet:
            return
        self.out.write("\r\x1b[K" + self._fit(f"{label} {text} -> {note}"))
        self.out.flush()
        self._dirty = True

    def error(self, message: str) -> None:
        self.end_line()
        print(shown(message), file=self.err, flush=True)

    def end_line(self) -> None:
        """Finish the in-place line so the next output starts on its own line."""
        if self._dirty:
            self.out.write("\n")
            self.out.flush()
            self._dirty = False

    @staticmethod
    def _fit(message: str) -> str:
        """``message`` cut to the terminal's width, so rewriting it in place works."""
        width = shutil.get_terminal_size().columns - 1
        return message if len(message) <= width else message[: width - 3] + "..."
