"""Hypothesis strategies for every CRCL record, made from the records' own declarations.

Each field's strategy follows its codec (numbers within their range, integers within
theirs, enumerations' choices, XML-safe text); poses get orthogonal axes of random
length; the few rules between fields (NumPositions, increasing or unique joint
numbers) are met by fixing the drawn values before the record is built.
"""

from __future__ import annotations

import math
from typing import Any

from hypothesis import strategies as st

from c2rviz.transports.crcl import (
    COMMAND_TYPES,
    ActuateJoints,
    ConfigureJointReports,
    CrclStatus,
    JointStatuses,
    MoveThroughTo,
    Point,
    Pose,
    PoseAndSet,
    Vector,
    record_fields,
)
from c2rviz.transports.crcl.binding import MANY, OPTIONAL, Nested, Record
from c2rviz.transports.crcl.primitives import POSITION_LIMIT
from c2rviz.transports.crcl.scalars import (
    BOOLEAN,
    COMMAND_ID,
    COUNT,
    DOUBLE,
    FRACTION,
    INT,
    JOINT_NUMBER,
    LONG,
    NMTOKEN,
    NON_NEGATIVE,
    POSITIVE,
    STRING,
    TOKEN,
    Scalar,
)

__all__ = ["commands", "pose_axes", "record_of", "statuses", "xml_text"]

# Every character XML 1.0 can carry (surrogates, U+FFFE/U+FFFF and C0 controls out).
xml_text = st.text(
    alphabet=st.characters(
        exclude_categories=["Cs"],
        exclude_characters="".join(map(chr, [*range(9), 11, 12, *range(14, 32)])) + "\ufffe\uffff",
    ),
    max_size=12,
)
_word = st.text(alphabet=st.characters(categories=["L", "N", "P", "S"]), min_size=1, max_size=6)
_SCALARS: dict[int, st.SearchStrategy[Any]] = {
    id(DOUBLE): st.floats(allow_nan=False, allow_infinity=False),
    id(POSITIVE): st.floats(min_value=0.0, exclude_min=True, allow_infinity=False),
    id(NON_NEGATIVE): st.floats(min_value=0.0, allow_infinity=False),
    id(FRACTION): st.floats(min_value=0.0, max_value=1.0),
    id(INT): st.integers(-(2**31), 2**31 - 1),
    id(LONG): st.integers(-(2**63), 2**63 - 1),
    id(COUNT): st.integers(0, 2**31 - 1),
    id(COMMAND_ID): st.integers(0, 2**63 - 1),
    id(JOINT_NUMBER): st.integers(1, 2**31 - 1),
    id(BOOLEAN): st.booleans(),
    id(STRING): xml_text,
    id(TOKEN): st.lists(_word, max_size=3).map(" ".join),
    id(NMTOKEN): st.from_regex(r"[A-Za-z0-9._:-]{1,8}", fullmatch=True),
}


def _scalar(codec: Scalar) -> st.SearchStrategy[Any]:
    if codec.choices:
        return st.sampled_from(codec.choices)
    return _SCALARS[id(codec)]


@st.composite
def pose_axes(draw: st.DrawFn) -> tuple[Vector, Vector]:
    """An x and a z axis: orthogonal directions of random (non-zero) length."""
    angles = draw(st.tuples(*[st.floats(-math.pi, math.pi)] * 3))
    a, b, c = angles
    z = (math.sin(a) * math.cos(b), math.sin(a) * math.sin(b), math.cos(a))
    helper = (1.0, 0.0, 0.0) if abs(z[0]) < 0.9 else (0.0, 1.0, 0.0)
    u = (z[1] * helper[2] - z[2] * helper[1], z[2] * helper[0] - z[0] * helper[2],
         z[0] * helper[1] - z[1] * helper[0])  # fmt: skip
    norm_u = math.sqrt(sum(v * v for v in u))
    e = [v / norm_u for v in u]
    w = (z[1] * e[2] - z[2] * e[1], z[2] * e[0] - z[0] * e[2], z[0] * e[1] - z[1] * e[0])
    x = [math.cos(c) * p + math.sin(c) * q for p, q in zip(e, w)]
    scale_x, scale_z = draw(st.sampled_from([1.0, 0.5, 3.0])), draw(st.sampled_from([1.0, 2.0]))
    return Vector(*(scale_x * v for v in x)), Vector(*(scale_z * v for v in z))


def _fields(cls: type[Record]) -> st.SearchStrategy[dict[str, Any]]:
    parts: dict[str, st.SearchStrategy[Any]] = {}
    for f in record_fields(cls):
        if isinstance(f.codec, Nested):
            one = st.one_of([record_of(option) for option in f.codec.classes])
        else:
            one = _scalar(f.codec)
        if f.kind == MANY:
            parts[f.name] = st.lists(one, min_size=f.min_count, max_size=f.min_count + 2).map(tuple)
        elif f.kind == OPTIONAL:
            parts[f.name] = st.none() | one
        else:
            parts[f.name] = one
    if cls is Point:  # a position lies within 1000 m in any length unit
        coordinate = st.floats(-POSITION_LIMIT, POSITION_LIMIT)
        parts = {"x": coordinate, "y": coordinate, "z": coordinate}
    if issubclass(cls, Pose):
        parts.pop("x_axis")
        parts.pop("z_axis")
        parts["axes"] = pose_axes()
    return st.fixed_dictionaries(parts)


def _fixed(cls: type[Record], values: dict[str, Any]) -> dict[str, Any]:
    if "axes" in values:
        values["x_axis"], values["z_axis"] = values.pop("axes")
    if cls is MoveThroughTo:
        values["num_positions"] = len(values["waypoints"])
    if cls is ConfigureJointReports:
        reports = {report.joint_number: report for report in values["reports"]}
        values["reports"] = tuple(reports[number] for number in sorted(reports))
    if cls is JointStatuses:
        statuses = {status.joint_number: status for status in values["statuses"]}
        values["statuses"] = tuple(statuses.values())
    if cls is ActuateJoints:
        joints = {joint.joint_number: joint for joint in values["joints"]}
        values["joints"] = tuple(joints.values())
    return values


_RECORDS: dict[type, st.SearchStrategy[Any]] = {}


def record_of(cls: type[Record]) -> st.SearchStrategy[Any]:
    """Valid instances of the record class ``cls``."""
    if cls not in _RECORDS:
        _RECORDS[cls] = _fields(cls).map(lambda values: cls(**_fixed(cls, values)))
    return _RECORDS[cls]


commands = st.one_of([record_of(cls) for cls in COMMAND_TYPES])
statuses = record_of(CrclStatus)
poses = st.one_of(record_of(Pose), record_of(PoseAndSet))
