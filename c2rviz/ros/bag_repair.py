"""Ending a rosbag2 MCAP bag whose writing stopped half-way (a full disk, a failed close, a kill).

``end_bag(folder)`` ends a bag left unfinished. ``end_mcap`` cuts its
``.mcap`` after the last whole record and ends it with MCAP's DataEnd and
Footer records and closing magic, without a summary section: what stays is
every chunk written whole before the failure. ``rosbags`` and the ``mcap``
package read such a file by scanning it, Foxglove as an unindexed file;
``ros2 bag play`` wants its index back first (``mcap recover`` writes it).
Then ``write_metadata`` writes the folder's ``metadata.yaml`` from what the
file really holds. Both write only a few hundred bytes, and the file is only
ever shortened before them.

The record layout is MCAP's public specification (https://mcap.dev/spec):
8 bytes of magic, then records of an opcode byte, a little-endian uint64
length and that many bytes.
"""

from __future__ import annotations

import json
import struct
from pathlib import Path
from typing import BinaryIO

from rosbags.interfaces import ConnectionExtRosbag2, Qos
from rosbags.rosbag2 import Reader
from rosbags.typesys.store import Typestore

MAGIC = b"\x89MCAP0\r\n"
_HEADER, _FOOTER, _DATA_END = 0x01, 0x02, 0x0F
_RECORD = struct.Struct("<BQ")  # opcode, length
_FOOTER_LENGTH = 20  # summary_start u64, summary_offset_start u64, summary_crc u32


def _record(opcode: int, body: bytes) -> bytes:
    return _RECORD.pack(opcode, len(body)) + body


def _string(text: str) -> bytes:
    data = text.encode()
    return struct.pack("<I", len(data)) + data


def _end_records() -> bytes:
    """DataEnd (no CRC), a Footer saying "no summary", and the closing magic."""
    footer = struct.pack("<QQI", 0, 0, 0)
    return _record(_DATA_END, struct.pack("<I", 0)) + _record(_FOOTER, footer) + MAGIC


def ended(file: BinaryIO) -> bool:
    """Whether an open MCAP file ends with a Footer record and the closing magic."""
    size = file.seek(0, 2)
    footer_at = size - len(MAGIC) - _RECORD.size - _FOOTER_LENGTH
    if footer_at < len(MAGIC):
        return False
    file.seek(footer_at)
    tail = file.read()
    return tail[: _RECORD.size] == _RECORD.pack(_FOOTER, _FOOTER_LENGTH) and tail.endswith(MAGIC)


def _whole_records_end(file: BinaryIO, size: int) -> tuple[int, bool]:
    """Where the whole records of the data section end, and whether a Header opens them."""
    file.seek(0)
    if file.read(len(MAGIC)) != MAGIC:
        return 0, False
    at, header = len(MAGIC), False
    while at + _RECORD.size <= size:
        file.seek(at)
        opcode, length = _RECORD.unpack(file.read(_RECORD.size))
        end = at + _RECORD.size + length
        if end > size or opcode in (_DATA_END, _FOOTER):  # cut short, or the summary follows
            break
        header = header or (at == len(MAGIC) and opcode == _HEADER)
        at = end
    return at, header


def end_mcap(path: Path) -> bool:
    """End an MCAP file that lacks its end; True if it had to be changed.

    A file that already ends with its Footer is left as it is. Otherwise it is
    cut after its last whole record (before any partial summary), and the end
    records are written: about 50 bytes, after freeing the partial record.

    Raises:
        OSError: the file cannot be opened, cut or written.
    """
    with open(path, "r+b") as file:
        if ended(file):
            return False
        size = file.seek(0, 2)
        end, has_header = _whole_records_end(file, size)
        if not has_header:  # not even the opening records: an empty bag
            end = 0
        file.truncate(end)
        file.seek(end)
        if not has_header:
            header = _string("ros2") + _string("c2rviz")
            file.write(MAGIC + _record(_HEADER, header))
        file.write(_end_records())
    return True


def qos_dict(qos: Qos) -> dict[str, object]:
    """One offered QoS profile as rosbag2 (metadata version 9) writes it."""

    def duration(value: tuple[int, int]) -> dict[str, int]:
        return {"sec": value[0], "nsec": value[1]}

    return {
        "history": qos.history.name.lower(),
        "depth": qos.depth,
        "reliability": qos.reliability.name.lower(),
        "durability": qos.durability.name.lower(),
        "deadline": duration(qos.deadline),
        "lifespan": duration(qos.lifespan),
        "liveliness": qos.liveliness.name.lower(),
        "liveliness_lease_duration": duration(qos.liveliness_lease_duration),
        "avoid_ros_namespace_conventions": qos.avoid_ros_namespace_conventions,
    }


def write_metadata(folder: Path, mcap: Path, typestore: Typestore) -> int:
    """Write ``folder/metadata.yaml`` (rosbag2 version 9) for what ``mcap`` holds.

    The file is JSON, which is YAML too. Returns the number of messages.

    Raises:
        OSError: it cannot be written.
        rosbags.rosbag2.ReaderError: ``mcap`` cannot be read.
    """
    with Reader(mcap) as reader:
        count = reader.message_count
        start = reader.start_time if count else 0
        duration = reader.end_time - 1 - start if count else 0
        topics = [
            {
                "topic_metadata": {
                    "name": conn.topic,
                    "type": conn.msgtype,
                    "serialization_format": "cdr",
                    "offered_qos_profiles": [
                        qos_dict(q)
                        for q in (
                            conn.ext.offered_qos_profiles
                            if isinstance(conn.ext, ConnectionExtRosbag2)
                            else []
                        )
                    ],
                    "type_description_hash": typestore.hash_rihs01(conn.msgtype),
                },
                "message_count": conn.msgcount,
            }
            for conn in reader.connections
        ]
    span = {
        "starting_time": {"nanoseconds_since_epoch": start},
        "duration": {"nanoseconds": duration},
    }
    info = {
        "version": 9,
        "storage_identifier": "mcap",
        "relative_file_paths": [mcap.name],
        **span,
        "message_count": count,
        "topics_with_message_count": topics,
        "compression_format": "",
        "compression_mode": "",
        "files": [{"path": mcap.name, **span, "message_count": count}],
        "custom_data": None,
        "ros_distro": "rosbags",
    }
    text = json.dumps({"rosbag2_bagfile_information": info}, indent=2) + "\n"
    temporary = folder / "metadata.yaml.tmp"
    temporary.write_text(text, encoding="utf-8")
    temporary.replace(folder / "metadata.yaml")
    return count


def end_bag(folder: Path, typestore: Typestore) -> int:
    """End the one ``.mcap`` of a bag folder if it lacks its end, and (re)write its metadata.

    Returns the number of messages it holds.

    Raises:
        OSError: a file cannot be read or written.
        FileNotFoundError: the folder holds no ``.mcap``, or more than one.
        rosbags.rosbag2.ReaderError: what is left cannot be read.
    """
    files = sorted(folder.glob("*.mcap"))
    if len(files) != 1:
        raise FileNotFoundError(f"{folder} holds {len(files)} .mcap files, not one")
    end_mcap(files[0])
    return write_metadata(folder, files[0], typestore)
