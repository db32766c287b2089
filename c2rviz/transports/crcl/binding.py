"""Frozen dataclasses bound to CRCL elements: one declaration gives reader, checker and writer.

A CRCL type is a ``Record`` subclass whose fields are declared with ``one`` (a required
element), ``opt`` (an optional one, ``None`` when absent) or ``many`` (a repeated one, a
tuple), each naming its element and its codec: a ``Scalar`` for text or a ``Nested`` for
a child record. Field order is the schema's sequence order, base type first, and the
writer follows it, so what is written is valid against the schema; the reader accepts
the children in any order (documented leniency) but refuses unknown, repeated or missing
ones. Every record is checked when built: by ``__post_init__`` when code builds it, by
the reader as it reads each value (the same checks, made once): an invalid record
cannot exist, so it cannot be written.

``Name`` (the optional first element of every CRCL type) is read into a field only
where a record declares one (commands); elsewhere it is accepted and ignored.
"""

from __future__ import annotations

import difflib
from dataclasses import dataclass, field, fields
from typing import Any, ClassVar, Final

from lxml import etree

from .errors import CrclError, CrclValueError, UnknownCrclType
from .scalars import COMMAND_ID, Scalar

XSI_NAMESPACE: Final = "http://www.w3.org/2001/XMLSchema-instance"
_XSI_TYPE: Final = "{" + XSI_NAMESPACE + "}type"
_KEY: Final = "crcl"
ONE, OPTIONAL, MANY = "one", "optional", "many"


class Nested:
    """A child element holding a record of one of ``classes`` (chosen by ``xsi:type``).

    Args:
        classes: The record classes allowed there.
        abstract: Whether the element's declared type is abstract: ``xsi:type`` is then
            required (and always written). Otherwise the first class is the declared
            type, used when ``xsi:type`` is absent and written without one.
    """

    def __init__(self, *classes: type[Record], abstract: bool = False) -> None:
        self.classes = classes
        self.by_type = {cls.XSI_TYPE: cls for cls in classes}
        self.default: type[Record] | None = None if abstract else classes[0]

    def choose(self, element: etree._Element) -> type[Record]:
        """The class an element's ``xsi:type`` (or its absence) selects."""
        written = element.get(_XSI_TYPE)
        if written is None:
            if self.default is None:
                known = ", ".join(self.by_type) if len(self.by_type) <= 6 else "a CRCL type"
                raise CrclValueError(f"xsi:type is missing (it must name {known})")
            return self.default
        name = written.strip().rpartition(":")[2]  # a QName; CRCL has no target namespace
        cls = self.by_type.get(name)
        if cls is None:
            names = list(self.by_type)
            raise UnknownCrclType(written, names, difflib.get_close_matches(name, names, 2))
        return cls


@dataclass(frozen=True)
class RecordField:
    """One element of a record's type, as declared (``record_fields`` lists them).

    Attributes:
        name: The dataclass field.
        tag: The element's name.
        codec: A ``Scalar`` for text, a ``Nested`` for a child record.
        kind: ``ONE`` (required), ``OPTIONAL`` (None when absent) or ``MANY`` (a tuple).
        min_count: The fewest occurrences allowed.
    """

    name: str
    tag: str
    codec: Scalar | Nested
    kind: str
    min_count: int

    def __post_init__(self) -> None:  # what the reader and writer ask for each element
        object.__setattr__(self, "many", self.kind == MANY)
        object.__setattr__(self, "open", f"<{self.tag}>")
        object.__setattr__(self, "close", f"</{self.tag}>")

    many: bool = field(init=False)
    open: str = field(init=False)
    close: str = field(init=False)


def one(tag: str, codec: Scalar | Nested) -> Any:
    """A required element ``tag`` (exactly once)."""
    return field(metadata={_KEY: (tag, codec, ONE, 1)})


def opt(tag: str, codec: Scalar | Nested) -> Any:
    """An optional element ``tag`` (at most once); the field is ``None`` when absent."""
    return field(default=None, metadata={_KEY: (tag, codec, OPTIONAL, 0)})


def many(tag: str, codec: Scalar | Nested, min_count: int = 0) -> Any:
    """A repeated element ``tag`` (``min_count`` or more times), held as a tuple."""
    if min_count:
        return field(metadata={_KEY: (tag, codec, MANY, min_count)})
    return field(default=(), metadata={_KEY: (tag, codec, MANY, 0)})


_SPECS: dict[type, tuple[RecordField, ...]] = {}
_BY_TAG: dict[type, dict[str, RecordField]] = {}
_WRITING: dict[type, tuple[tuple[Any, ...], ...]] = {}


def record_fields(cls: type) -> tuple[RecordField, ...]:
    """The elements of a ``Record`` class, in the schema's sequence order."""
    return _spec(cls)


def _spec(cls: type) -> tuple[RecordField, ...]:
    spec = _SPECS.get(cls)
    if spec is None:
        undeclared = [f.name for f in fields(cls) if _KEY not in f.metadata]
        if undeclared:
            raise TypeError(f"{cls.__name__} fields {undeclared} are not declared elements")
        spec = tuple(RecordField(f.name, *f.metadata[_KEY]) for f in fields(cls))
        _SPECS[cls] = spec
        _BY_TAG[cls] = {f.tag: f for f in spec}
    return spec


@dataclass(frozen=True)
class Record:
    """A CRCL complex type: built only with valid values (else ``CrclValueError``)."""

    XSI_TYPE: ClassVar[str] = ""
    """The schema's name of the type, written as ``xsi:type`` where one is needed."""

    def __post_init__(self) -> None:
        for f in _spec(type(self)):
            value = getattr(self, f.name)
            try:
                checked = _checked(f, value)
            except CrclError as error:
                raise error.within(f.tag) from None
            if checked is not value:
                object.__setattr__(self, f.name, checked)
        self._check()

    def _check(self) -> None:
        """Rules between fields (a subclass's hook); raise ``CrclValueError``."""


def _checked(f: RecordField, value: Any) -> Any:
    if f.kind == MANY:
        if not isinstance(value, (tuple, list)):
            raise CrclValueError(f"must be a sequence of {f.tag} values, got {value!r}")
        if len(value) < f.min_count:
            raise CrclValueError(f"needs at least {f.min_count} {f.tag}, got {len(value)}")
        items = tuple(_checked_one(f.codec, item) for item in value)
        same = isinstance(value, tuple) and all(a is b for a, b in zip(items, value))
        return value if same else items
    if value is None:
        if f.kind == ONE:
            raise CrclValueError("is required")
        return None
    return _checked_one(f.codec, value)


def _checked_one(codec: Scalar | Nested, value: Any) -> Any:
    if isinstance(codec, Scalar):
        return codec.check(value)
    if type(value) not in codec.classes:
        names = ", ".join(cls.__name__ for cls in codec.classes)
        raise CrclValueError(f"must be one of {names}, got {type(value).__name__}")
    return value


def read_record(codec: Nested, element: etree._Element) -> Record:
    """Build the record an element holds; errors name the path below ``element``."""
    try:
        cls = codec.choose(element)
    except CrclError as error:
        if any(_is_command(cls) for cls in codec.classes):
            error.command_id = _peek_command_id(element)
        raise
    try:
        return _read_fields(cls, element)
    except CrclError as error:
        if error.command_id is None and _is_command(cls):
            error.command_type = cls.XSI_TYPE
            error.command_id = _peek_command_id(element)
        raise


def _is_command(cls: type) -> bool:
    return any(f.name == "command_id" for f in _spec(cls))


def _read_fields(cls: type[Record], element: etree._Element) -> Record:
    """The record ``element`` holds, each value checked as read; ``__init__`` is bypassed
    because everything it would check (values, counts, classes) is checked here."""
    spec = _spec(cls)
    by_tag = _BY_TAG[cls]
    values: dict[str, Any] = {}
    for child in element:
        tag = child.tag
        if not isinstance(tag, str):
            continue  # comments and processing instructions (the parser removes them)
        if tag[0] == "{":
            tag = tag.rpartition("}")[2]
        f = by_tag.get(tag)
        if f is None:
            if tag == "Name":
                continue
            expected = ", ".join(by_tag) or "no child elements"
            raise CrclValueError(f"unexpected element <{tag[:40]}> (expected: {expected})")
        if f.many:
            items = values.setdefault(f.name, [])
            label = f"{tag}[{len(items) + 1}]"
        elif f.name in values:
            raise CrclValueError(f"<{tag}> appears more than once (at most once)")
        else:
            label = tag
        codec = f.codec
        try:
            if isinstance(codec, Nested):
                value: Any = read_record(codec, child)
            elif len(child):
                raise CrclValueError(f"must hold a {codec.kind} value, not elements")
            else:
                value = codec.check(codec.read(child.text or ""))
        except CrclError as error:
            raise error.within(label) from None
        if f.many:
            items.append(value)
        else:
            values[f.name] = value
    for f in spec:
        value = values.get(f.name)
        if value is None:
            if f.kind == ONE:
                raise CrclValueError(f"missing required element <{f.tag}>")
            values[f.name] = () if f.many else None
            value = ()
        elif f.many:
            values[f.name] = tuple(value)
        if f.many and len(value) < f.min_count:
            problem = f"needs at least {f.min_count} {f.tag}, got {len(value)}"
            raise CrclValueError(problem).within(f.tag)
    record = object.__new__(cls)
    record.__dict__.update(values)
    record._check()
    return record


def _peek_command_id(element: etree._Element) -> int | None:
    """The CommandID of a command element if it has a valid one (for error messages)."""
    for child in element:
        if isinstance(child.tag, str) and child.tag.rpartition("}")[2] == "CommandID":
            try:
                value = COMMAND_ID.read(child.text or "")
                return int(COMMAND_ID.check(value))
            except CrclError:
                return None
    return None


def write_record(
    record: Record, tag: str, out: list[str], codec: Nested | None = None, attributes: str = ""
) -> None:
    """Append the element ``tag`` holding ``record`` to ``out`` (compact: no whitespace).

    Args:
        record: What to write.
        tag: The element's name.
        out: Text pieces, joined by the caller.
        codec: The element's declaration; ``xsi:type`` is written unless the record's
            class is the declared (non-abstract) type.
        attributes: Extra attribute text for a root (e.g. the xmlns:xsi declaration).
    """
    cls = type(record)
    if codec is not None and cls is not codec.default:
        out.append(f'<{tag}{attributes} xsi:type="{cls.XSI_TYPE}">')
    else:
        out.append(f"<{tag}{attributes}>")
    fields_of = record.__dict__
    plan = _WRITING.get(cls)
    if plan is None:
        plan = _WRITING[cls] = tuple(
            (f.name, f.tag, f.codec if isinstance(f.codec, Nested) else None, f.many,
             f.open, f.close, f.codec.format if isinstance(f.codec, Scalar) else str)
            for f in _spec(cls)
        )  # fmt: skip
    for name, child, nested, repeated, opening, closing, text in plan:
        value = fields_of[name]
        if value is None:
            continue
        if nested is not None:
            for item in value if repeated else (value,):
                write_record(item, child, out, nested)
        elif repeated:
            out.extend(opening + text(item) + closing for item in value)
        else:
            out.append(opening + text(value) + closing)
    out.append(f"</{tag}>")
