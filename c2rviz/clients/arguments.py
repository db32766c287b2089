"""Checking a client method's arguments before anything is sent, and writing them as text.

Each check names the method and the argument (``ArgumentTypeError`` for a wrong type,
``ArgumentError`` for a wrong count or value). Numbers are written in their shortest
exact form (``repr``), so the server reads exactly the value given.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Iterable, Sequence

from .errors import ArgumentError, ArgumentTypeError

__all__ = ["choice", "flag", "number", "numbers_text", "values", "word"]


def number(method: str, argument: str, value: object) -> float:
    """``value`` as a finite float: an int or float (numpy's too), not a bool or a string."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ArgumentTypeError(method, argument, f"expected a number, got {_kind(value)}")
    result = float(value)
    if not math.isfinite(result):
        raise ArgumentError(method, argument, f"{result} is not a finite number")
    return result


def values(
    method: str, argument: str, given: object, count: int | None = None
) -> tuple[float, ...]:
    """``given`` as finite floats: a sequence (or other iterable) of numbers, not a string.

    Args:
        count: How many there must be (None: any number, at least one).
    """
    if isinstance(given, (str, bytes)) or not isinstance(given, Iterable):
        raise ArgumentTypeError(
            method, argument, f"expected a sequence of numbers, got {_kind(given)}"
        )
    items = list(given)
    out = []
    for i, item in enumerate(items):
        if isinstance(item, bool) or not isinstance(item, numbers.Real):
            raise ArgumentTypeError(method, argument, f"item {i} is {_kind(item)}, not a number")
        value = float(item)
        if not math.isfinite(value):
            raise ArgumentError(method, argument, f"item {i} ({value}) is not a finite number")
        out.append(value)
    if count is not None and len(out) != count:
        raise ArgumentError(method, argument, f"needs {count} values, got {len(out)}")
    if not out:
        raise ArgumentError(method, argument, "needs at least one value")
    return tuple(out)


def indices(method: str, argument: str, given: object) -> tuple[int, ...]:
    """``given`` as joint indices: a sequence of ints >= 0 (or one int)."""
    items = [given] if isinstance(given, int) and not isinstance(given, bool) else given
    if isinstance(items, (str, bytes)) or not isinstance(items, Iterable):
        raise ArgumentTypeError(method, argument, f"expected joint indices, got {_kind(given)}")
    out = []
    for i, item in enumerate(items):
        if isinstance(item, bool) or not isinstance(item, numbers.Integral):
            raise ArgumentTypeError(method, argument, f"item {i} is {_kind(item)}, not an int")
        if item < 0:
            raise ArgumentError(method, argument, f"item {i} ({item}) is below 0")
        out.append(int(item))
    if not out:
        raise ArgumentError(method, argument, "needs at least one index")
    return tuple(out)


def word(method: str, argument: str, given: object) -> str:
    """``given`` as one word: a non-empty string without spaces or control characters."""
    if not isinstance(given, str):
        raise ArgumentTypeError(method, argument, f"expected a string, got {_kind(given)}")
    if not given or not given.isascii() or not given.isprintable() or " " in given:
        raise ArgumentError(method, argument, f"{given!r} is not one plain word")
    if "#" in given:
        raise ArgumentError(method, argument, f"{given!r} has a '#' (a comment would start)")
    return given


def choice(method: str, argument: str, given: object, choices: Sequence[str]) -> str:
    """``given``, one of ``choices`` (lower case)."""
    text = word(method, argument, given).lower()
    if text not in choices:
        raise ArgumentError(method, argument, f"{given!r} is not one of {', '.join(choices)}")
    return text


def flag(method: str, argument: str, given: object) -> bool:
    """``given`` as a bool (True or False only)."""
    if not isinstance(given, bool):
        raise ArgumentTypeError(method, argument, f"expected True or False, got {_kind(given)}")
    return given


def numbers_text(items: Iterable[float]) -> str:
    """Values as the protocol writes a list: comma-separated, each exact."""
    return ",".join(map(repr, items))


def _kind(value: object) -> str:
    if isinstance(value, str):
        return f"a string ({value[:20]!r})"
    return f"{type(value).__name__}"
