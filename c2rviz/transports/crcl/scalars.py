"""The text values of CRCL: numbers, integers, booleans, strings and enumerations.

Each ``Scalar`` reads an element's text (the XML Schema lexical form), checks a Python
value (type and range) and writes it back. Reading is strict where Python is lax:
``float()`` would take ``"nan"``, ``"inf"``, ``"1_0"`` and ``" 1"``-with-tabs; CRCL
numbers must match the xs:double form and be finite. Floats are written with
``repr`` (the shortest text that reads back to the same float), so a value survives
write-then-read exactly.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from c2rviz.errors import shown

from .errors import CrclValueError

_DOUBLE = re.compile(r"[+-]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")
_SPECIAL = {"NaN", "INF", "+INF", "-INF", "nan", "inf", "-inf", "+inf", "infinity"}
_INTEGER = re.compile(r"[+-]?[0-9]{1,30}")
_WHITESPACE = re.compile(r"[ \t\n\r]+")
_NMTOKEN = re.compile(r"[\w.\-:\u00b7]+")
# Characters XML 1.0 cannot carry at all (not even as character references).
_NOT_XML = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\ud800-\udfff\ufffe\uffff]")
_ESCAPES = str.maketrans({"&": "&amp;", "<": "&lt;", ">": "&gt;", "\r": "&#13;"})


@dataclass(frozen=True)
class Scalar:
    """How one kind of text value is read, checked and written.

    Attributes:
        kind: The schema's name for it, for messages (``"xs:double"``).
        parse: Text (already whitespace-processed) -> value; raises ``CrclValueError``.
        check: Value -> the value to store (e.g. an int made float); raises
            ``CrclValueError`` if it has the wrong type or is out of range.
        format: Value -> text, already escaped for XML content.
        collapse: Whether leading/trailing whitespace is dropped before ``parse``
            (every type but xs:string).
        choices: The allowed values of an enumeration; empty for other types.
    """

    kind: str
    parse: Callable[[str], Any]
    check: Callable[[Any], Any]
    format: Callable[[Any], str]
    collapse: bool = True
    choices: tuple[str, ...] = ()

    def read(self, text: str) -> Any:
        """The value an element's text stands for (range checks come with ``check``)."""
        return self.parse(text.strip(" \t\n\r") if self.collapse else text)


def _parse_double(text: str) -> float:
    if _DOUBLE.fullmatch(text):
        value = float(text)
        if math.isinf(value):
            raise CrclValueError(f"{shown(text)} is too large for a double")
        return value
    if text in _SPECIAL or text.lower() in _SPECIAL:
        raise CrclValueError(f"{text} is not allowed: numbers must be finite")
    if not text:
        raise CrclValueError("empty: a number is needed (xs:double, e.g. 0.25 or -1.5e-3)")
    raise CrclValueError(f"{shown(text)} is not a number (xs:double, e.g. 0.25 or -1.5e-3)")


def number(
    low: float | None = None, high: float | None = None, *, open_low: bool = False
) -> Scalar:
    """An xs:double that must be finite and, if given, within ``low``..``high``.

    Args:
        low: Smallest allowed value (or bound, if ``open_low``); None for no bound.
        high: Largest allowed value; None for no bound.
        open_low: Whether ``low`` itself is excluded (``> 0`` rather than ``>= 0``).
    """
    if low is not None and high is not None:
        rule = f"within {low:g}..{high:g}"
    elif low is not None:
        rule = f"{'>' if open_low else '>='} {low:g}"
    else:
        rule = ""

    def check(value: Any) -> float:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise CrclValueError(f"{value!r} is not a number")
        value = float(value)
        if not math.isfinite(value):
            raise CrclValueError(f"{value!r} is not allowed: numbers must be finite")
        too_low = low is not None and (value <= low if open_low else value < low)
        if too_low or (high is not None and value > high):
            raise CrclValueError(f"{value!r} is out of range: must be {rule}")
        return value

    return Scalar("xs:double", _parse_double, check, repr)


def integer(low: int, high: int, kind: str, rule: str = "") -> Scalar:
    """An integer within ``low``..``high`` (the type's range or a tighter rule)."""
    rule = rule or f"within {low}..{high}"

    def parse(text: str) -> int:
        if _INTEGER.fullmatch(text):
            return int(text)
        if not text:
            raise CrclValueError(f"empty: an integer is needed ({kind})")
        raise CrclValueError(f"{shown(text)} is not an integer ({kind})")

    def check(value: Any) -> int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise CrclValueError(f"{value!r} is not an integer ({kind})")
        if not low <= value <= high:
            raise CrclValueError(f"{value} is out of range: must be {rule}")
        return value

    return Scalar(kind, parse, check, str)


def _parse_boolean(text: str) -> bool:
    if text in ("true", "1"):
        return True
    if text in ("false", "0"):
        return False
    raise CrclValueError(f"{shown(text)} is not a boolean (true, false, 1 or 0)")


def _check_boolean(value: Any) -> bool:
    if not isinstance(value, bool):
        raise CrclValueError(f"{value!r} is not a boolean")
    return value


def _check_text(value: Any) -> str:
    if not isinstance(value, str):
        raise CrclValueError(f"{value!r} is not text")
    bad = _NOT_XML.search(value)
    if bad:
        raise CrclValueError(f"character {bad.group()!r} cannot be written in XML")
    return value


def _check_token(value: Any) -> str:
    value = _check_text(value)
    if value != " ".join(_WHITESPACE.split(value.strip(" \t\n\r"))):
        raise CrclValueError(
            f"{shown(value)} is not a token (no leading, trailing or double spaces)"
        )
    return value


def _check_nmtoken(value: Any) -> str:
    value = _check_text(value)
    if not _NMTOKEN.fullmatch(value):
        raise CrclValueError(f"{shown(value)} is not a name (letters, digits, . - _ :)")
    return value


def _escape(value: str) -> str:
    return value.translate(_ESCAPES)


def _parse_token(text: str) -> str:
    return " ".join(_WHITESPACE.split(text)) if text else text


def xml_safe_text(text: str) -> str:
    """``text`` with every character that XML 1.0 cannot carry replaced by U+FFFD.

    Use it on text from outside (an error message quoting a client's bytes) before
    putting it in a status, whose strings are checked like any other value.
    """
    return _NOT_XML.sub("\ufffd", text)


def enumeration(*choices: str) -> Scalar:
    """A token that must be one of ``choices`` (the schema's enumeration)."""
    listed = ", ".join(choices)

    def parse(text: str) -> str:
        text = _parse_token(text)
        if text not in choices:
            raise CrclValueError(f"{shown(text)} is not one of: {listed}")
        return text

    def check(value: Any) -> str:
        if value not in choices:
            raise CrclValueError(f"{value!r} is not one of: {listed}")
        return str(value)

    return Scalar("enumeration", parse, check, str, choices=choices)


DOUBLE = number()
POSITIVE = number(0.0, open_low=True)
NON_NEGATIVE = number(0.0)
FRACTION = number(0.0, 1.0)
INT = integer(-(2**31), 2**31 - 1, "xs:int")
LONG = integer(-(2**63), 2**63 - 1, "xs:long")
COUNT = integer(0, 2**31 - 1, "xs:int", ">= 0")
COMMAND_ID = integer(0, 2**63 - 1, "xs:long", "a non-negative integer")
JOINT_NUMBER = integer(1, 2**31 - 1, "xs:int", ">= 1 (joints are numbered from 1)")
BOOLEAN = Scalar("xs:boolean", _parse_boolean, _check_boolean, lambda v: "true" if v else "false")
STRING = Scalar("xs:string", lambda text: text, _check_text, _escape, collapse=False)
TOKEN = Scalar("xs:token", _parse_token, _check_token, _escape)
NMTOKEN = Scalar("xs:NMTOKEN", _parse_token, _check_nmtoken, _escape)
