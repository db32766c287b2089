"""A bag's ``sensor_msgs/JointState`` topic as a checked stream of chain positions.

``JointStateBag.open(path, topic=None)`` opens a rosbag2 folder, a bare
``.mcap`` or ``.db3`` file, or a ROS 1 ``.bag`` (through
``rosbags.highlevel.AnyReader``) and chooses its JointState topic (the only one,
or ``topic``). Its time axis is the bag's: seconds [s] of log (receive) time
from the bag's first message, what ``ros2 bag play`` paces by; a span is
``start_s`` to ``start_s + duration_s`` on it (to the end when
``duration_s`` is None), read through the bag's index, never the whole bag.

``check(chain, start_s, duration_s)`` reads exactly that span of the topic and
raises at the first thing a player must not send (each error one line, a
``BagError``): a NaN or infinite position, a message naming some of the chain's
joints but not all (the missing one named), names and positions of unequal
length, a joint named twice, header stamps going backwards, or no message with the
chain's joints at all. A bag file (or a file of a bag folder) that is not a regular
file (a FIFO) is refused before it is opened. It returns warnings, each once: joints
the bag names that the chain does not have (ignored), and messages naming none of the
chain's joints (skipped: a gripper's states on the same topic). ``samples`` yields the same
span as ``(t_s, positions in chain order)``, lazily, with the same checks, so
memory stays flat however long the bag.
"""

from __future__ import annotations

import math
from collections.abc import Generator, Iterator, Sequence
from math import isfinite
from pathlib import Path
from typing import Any

from rosbags.highlevel import AnyReader

from .cdr import JointStateDecoder
from .errors import (
    AmbiguousTopic,
    BadSample,
    BagCorrupted,
    BagError,
    EmptySpan,
    MissingJoint,
    NoJointStateTopic,
    NotABag,
    StampsBackwards,
    UnknownTopic,
)

JOINT_STATE_TYPES = ("sensor_msgs/msg/JointState", "sensor_msgs/JointState")
_SUFFIXES = (".mcap", ".db3", ".bag")
_KINDS = "a rosbag2 folder (with metadata.yaml), an .mcap or .db3 file, or a ROS 1 .bag"
# rosbags' words for a file that is not a bag at all (the rest means damaged).
_NOT_A_BAG = (
    "file magic is invalid",
    "seems to be empty",
    "profile is not",
    "unrecognized storage",
    "file is not a database",
)


def _one_line(exc: BaseException) -> str:
    """The first line of an exception's message (a YAML error adds a picture of the line)."""
    lines = str(exc).strip().splitlines()
    return lines[0].strip() if lines else type(exc).__name__


def _classify(path: Path, exc: BaseException) -> BagError:
    """Our error for what rosbags raised while opening ``path``."""
    text = _one_line(exc)
    if isinstance(exc, FileNotFoundError) and path.is_dir():
        return NotABag(str(path), f"is a folder without metadata.yaml; give {_KINDS}")
    if any(words in text.lower() for words in _NOT_A_BAG):
        return NotABag(str(path), f"is not a bag ({text.rstrip('.')}); give {_KINDS}")
    hint = " (`mcap recover` can save what it holds)" if "end magic" in text else ""
    return BagCorrupted(str(path), f"is truncated or damaged: {text}{hint}")


class JointStateBag:
    """One JointState topic of an open bag (close it, or use ``with``)."""

    def __init__(self, path: Path, reader: AnyReader, topic: str) -> None:
        """Use ``open``."""
        self.path = path
        self.reader = reader
        self.topic = topic
        self.connections = [c for c in reader.connections if c.topic == topic]
        self.msgtype = self.connections[0].msgtype
        self.count = sum(c.msgcount for c in self.connections)
        """Messages on the topic (in the whole bag)."""
        self.start_ns = reader.start_time
        """The bag's first log time [ns]: t = 0."""
        self.duration_s = max(0, reader.end_time - 1 - reader.start_time) / 1e9
        """The bag's length [s]: its last message's log time (end_time is 1 ns past it)."""
        formats = {getattr(c.ext, "serialization_format", "ros1") for c in self.connections}
        self._wire = formats.pop() if len(formats) == 1 else None  # "cdr", "ros1" or mixed

    @classmethod
    def open(cls, path: str | Path, topic: str | None = None) -> JointStateBag:
        """Open the bag at ``path`` and choose its JointState topic.

        Args:
            path: A rosbag2 folder, an ``.mcap`` or ``.db3`` file, or a ROS 1 ``.bag``.
            topic: The JointState topic (with or without its leading ``/``); None for
                the only one.

        Raises:
            NotABag: nothing there, or not a bag.
            BagCorrupted: a bag that is truncated or damaged.
            NoJointStateTopic: no JointState topic (its topics are listed).
            AmbiguousTopic: several and ``topic`` None (they are named).
            UnknownTopic: ``topic`` is not one of them.
        """
        path = Path(path)
        if not path.exists():
            raise NotABag(str(path), f"does not exist; give {_KINDS}")
        if not path.is_dir() and path.suffix not in _SUFFIXES:
            raise NotABag(str(path), f"is not a bag (by its name); give {_KINDS}")
        _regular_files(path)
        try:
            reader = AnyReader([path])
            reader.open()
        except Exception as exc:  # rosbags' readers raise many kinds; each becomes ours
            raise _classify(path, exc) from None
        try:
            chosen = _choose(path, reader, topic)
        except BagError:
            reader.close()
            raise
        return cls(path, reader, chosen)

    def close(self) -> None:
        """Close the bag's files."""
        if self.reader.stack is not None:
            self.reader.close()

    def __enter__(self) -> JointStateBag:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def check(
        self, chain_names: Sequence[str], start_s: float = 0.0, duration_s: float | None = None
    ) -> list[str]:
        """Read the span of the topic and raise at anything unplayable; return warnings.

        Args:
            chain_names: The robot's chain joints, in chain order.
            start_s: Where the span starts [s from the bag's start].
            duration_s: Its length [s], or None to the bag's end.

        Raises:
            BagError: the first problem (see the module), or a span outside the bag.
        """
        warnings: list[str] = []
        for _ in self._scan(chain_names, start_s, duration_s, warnings):
            pass
        return warnings

    def samples(
        self,
        chain_names: Sequence[str],
        start_s: float = 0.0,
        duration_s: float | None = None,
        warnings: list[str] | None = None,
    ) -> Generator[tuple[float, tuple[float, ...]], None, None]:
        """Yield ``(t_s, positions)`` of the span, lazily: t [s from the bag's start],
        the chain's positions [rad or m] in chain order. Raises as ``check`` does, and
        appends its warnings to ``warnings`` (if given) once the span is read."""
        return self._scan(chain_names, start_s, duration_s, [] if warnings is None else warnings)

    # Reading.

    def _span(self, start_s: float, duration_s: float | None) -> tuple[int, int | None]:
        if not (math.isfinite(start_s) and start_s >= 0):
            raise EmptySpan(str(self.path), f"start {start_s} s is not a time in the bag (>= 0)")
        if duration_s is not None and not (math.isfinite(duration_s) and duration_s > 0):
            raise EmptySpan(str(self.path), f"duration {duration_s} s is not a positive time")
        if start_s > self.duration_s:
            raise EmptySpan(
                str(self.path), f"starts at {start_s} s, after its end ({self.duration_s:.3f} s)"
            )
        start = self.start_ns + round(start_s * 1e9)
        return start, None if duration_s is None else start + round(duration_s * 1e9)

    def _messages(self, start: int, stop: int | None) -> Iterator[tuple[int, bytes]]:
        messages = self.reader.messages(connections=self.connections, start=start, stop=stop)
        while True:
            try:
                _, log_ns, raw = next(messages)
            except StopIteration:
                return
            except Exception as exc:  # a damaged chunk or record, deep in rosbags
                raise BagCorrupted(str(self.path), f"is damaged: {_one_line(exc)}") from None
            yield log_ns, raw

    def _scan(
        self,
        chain_names: Sequence[str],
        start_s: float,
        duration_s: float | None,
        warnings: list[str],
    ) -> Generator[tuple[float, tuple[float, ...]], None, None]:
        start, stop = self._span(start_s, duration_s)
        decoder = JointStateDecoder(ros1=self._wire == "ros1")
        chain = tuple(chain_names)
        where: dict[tuple[str, ...], list[int] | None] = {}  # names -> chain's indices
        extra: dict[str, None] = {}
        previous_stamp, skipped, sent = -(2**63), 0, 0
        first_skipped: tuple[float, tuple[str, ...]] | None = None
        path = str(self.path)
        for log_ns, raw in self._messages(start, stop):
            t_s = (log_ns - self.start_ns) / 1e9
            stamp_ns, names, positions = self._decode(decoder, raw, t_s)
            if len(positions) != len(names):
                raise BadSample(
                    path,
                    f"the JointState at {t_s:.6f} s has {len(names)} names and "
                    f"{len(positions)} positions",
                )
            index = where.get(names, ...)
            if index is ...:
                index = where[names] = _chain_index(path, chain, names, t_s)
                extra.update(dict.fromkeys(n for n in names if n not in chain))
            if index is None:
                skipped += 1
                first_skipped = first_skipped or (t_s, names)
                continue
            values = tuple([positions[k] for k in index])
            if not all(map(isfinite, values)):
                k = next(k for k, value in enumerate(values) if not isfinite(value))
                raise BadSample(
                    path, f"joint {chain[k]!r} is {values[k]} at {t_s:.6f} s (not a finite number)"
                )
            if stamp_ns < previous_stamp:
                raise StampsBackwards(path, t_s, stamp_ns / 1e9, previous_stamp / 1e9)
            previous_stamp = stamp_ns
            sent += 1
            yield t_s, values
        if not sent and first_skipped is not None:  # names, but none of the chain's
            raise MissingJoint(path, chain[0], *first_skipped)
        if not sent:
            end = "the end" if stop is None else f"{(stop - self.start_ns) / 1e9:g} s"
            raise EmptySpan(
                path,
                f"has no JointState on {self.topic} with the chain's joints "
                f"({', '.join(chain)}) from {start_s:g} s to {end}",
            )
        if extra:
            warnings.append(
                f"{self.topic} also names joints the chain does not have, ignored: "
                + ", ".join(extra)
            )
        if skipped:
            warnings.append(
                f"{skipped} JointState messages on {self.topic} name none of the chain's joints "
                "and were skipped"
            )

    def _decode(
        self, decoder: JointStateDecoder, raw: bytes, t_s: float
    ) -> tuple[int, tuple[str, ...], tuple[float, ...]]:
        try:
            decoded = decoder.decode(raw) if self._wire in ("cdr", "ros1") else None
            if decoded is not None:
                return decoded
            message: Any = self.reader.deserialize(raw, self.msgtype)
        except Exception as exc:  # a message whose bytes do not fit JointState
            raise BagCorrupted(
                str(self.path), f"holds a damaged JointState at {t_s:.6f} s: {_one_line(exc)}"
            ) from None
        stamp = message.header.stamp
        names = tuple(message.name)
        positions = tuple(float(value) for value in message.position)
        return stamp.sec * 1_000_000_000 + stamp.nanosec, names, positions


def _regular_files(path: Path) -> None:
    """Refuse a bag file, or a file of a bag folder, that is not a regular file: a FIFO
    or a device would be read forever (a symlink to a regular file is one).

    Raises:
        NotABag: naming the file.
    """
    files = [entry for entry in path.iterdir() if not entry.is_dir()] if path.is_dir() else [path]
    for file in files:
        if not file.is_file():
            raise NotABag(str(file), f"is not a regular file (a FIFO or a device?); give {_KINDS}")


def _choose(path: Path, reader: AnyReader, topic: str | None) -> str:
    ours = sorted({c.topic for c in reader.connections if c.msgtype in JOINT_STATE_TYPES})
    if not ours:
        listed = sorted((name, info.msgtype or "?") for name, info in reader.topics.items())
        raise NoJointStateTopic(str(path), listed)
    if topic is None:
        if len(ours) > 1:
            raise AmbiguousTopic(str(path), ours)
        return ours[0]
    wanted = topic if topic.startswith("/") else "/" + topic
    if wanted not in ours:
        raise UnknownTopic(str(path), topic, ours)
    return wanted


def _chain_index(
    path: str, chain: tuple[str, ...], names: tuple[str, ...], t_s: float
) -> list[int] | None:
    """Where each chain joint is in ``names``; None if it names none of them."""
    position = {name: k for k, name in enumerate(names)}
    if len(position) != len(names):  # which value would count? rosbridge refuses it too
        twice = next(name for k, name in enumerate(names) if name in names[:k])
        raise BadSample(path, f"the JointState at {t_s:.6f} s names joint {twice!r} twice")
    missing = [name for name in chain if name not in position]
    if len(missing) == len(chain):
        return None
    if missing:
        raise MissingJoint(path, missing[0], t_s, names)
    return [position[name] for name in chain]
