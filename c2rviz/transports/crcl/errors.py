"""The CRCL errors: one class, ``CrclError``, with a subclass per way a document fails.

Every error carries the ``command_id`` of the command it is about (``None`` when the
document never got that far) and a description fit for a status's ``StateDescription``:
what was wrong, where (the element path from the document's root) and what is valid.
"""

from __future__ import annotations

from collections.abc import Sequence

from c2rviz.errors import C2rvizError, shown


class CrclError(C2rvizError):
    """A CRCL byte stream, document or value that c2rviz refuses.

    Attributes:
        problem: What was wrong, without the context (e.g. ``'abc' is not a number``).
        path: The elements from below the document's root down to the bad one, e.g.
            ``("CRCLCommand", "EndPosition", "Point", "X")``; empty if not about one element.
        command_id: The ``CommandID`` of the command the error is about, or ``None``
            when it is unknown (not read yet, missing or itself bad).
        command_type: The command's ``xsi:type`` (e.g. ``"MoveToType"``) when known.
    """

    def __init__(
        self,
        problem: str,
        *,
        path: Sequence[str] = (),
        command_id: int | None = None,
        command_type: str | None = None,
    ) -> None:
        super().__init__(problem)
        self.problem = problem
        self.path = tuple(path)
        self.command_id = command_id
        self.command_type = command_type

    @property
    def description(self) -> str:
        """The whole message: the command (if known), the element path and the problem."""
        where = "/".join(self.path)
        text = f"{where}: {self.problem}" if where else self.problem
        if self.command_type is not None and self.command_id is not None:
            return f"{self.command_type} (CommandID {self.command_id}): {text}"
        if self.command_type is not None:
            return f"{self.command_type}: {text}"
        if self.command_id is not None:
            return f"CommandID {self.command_id}: {text}"
        return text

    def within(self, segment: str) -> CrclError:
        """Put ``segment`` (the enclosing element) in front of the path; return self."""
        self.path = (segment, *self.path)
        return self

    def __str__(self) -> str:
        return self.description


class CrclFramingError(CrclError):
    """A byte stream that cannot be split into documents at this point.

    Attributes:
        recoverable: True when the splitter skips ahead to the next plausible document
            and goes on; False when the stream cannot be trusted any more and the
            connection should be closed after reporting the error.
    """

    def __init__(self, problem: str, *, recoverable: bool) -> None:
        super().__init__(problem)
        self.recoverable = recoverable


class CrclSyntaxError(CrclError):
    """A document that is not well-formed XML, not UTF-8, or uses a forbidden construct
    (a DOCTYPE, an entity declaration), or whose root is not the one expected."""


class CrclValueError(CrclError):
    """A well-formed document with a missing, surplus, malformed or out-of-range value."""


class UnknownCrclType(CrclError):
    """An ``xsi:type`` that is not among the types allowed where it stands.

    Attributes:
        xsi_type: The type as written.
        known: The type names allowed there.
    """

    def __init__(self, xsi_type: str, known: Sequence[str], suggestions: Sequence[str]) -> None:
        self.xsi_type = xsi_type
        self.known = tuple(known)
        if len(self.known) <= 6:
            choices = "one of " + ", ".join(self.known)
        else:
            choices = f"one of the {len(self.known)} CRCL types, e.g. " + ", ".join(self.known[:4])
        hint = f"; did you mean {' or '.join(suggestions)}?" if suggestions else ""
        super().__init__(f"unknown xsi:type {shown(xsi_type)} ({choices}){hint}")
