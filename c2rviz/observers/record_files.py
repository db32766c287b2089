"""A recording's files: written under private names, put in place whole, never through a link.

``RecordFiles(folder, name)`` hands out the private names a recording writes
while it runs: ``.NAME.TOKEN.txt.part`` (the command file's body),
``.NAME.TOKEN.csv``, ``.NAME.TOKEN.html`` and the bag ``.NAME.TOKEN.bag/NAME/``,
TOKEN being random for each recording. Files are created with ``O_EXCL`` and
``O_NOFOLLOW``, so nothing already there (a file, a planted link) is ever
opened or followed. When the recording is finished, ``publish`` renames each
into its final name (``NAME.txt``, ``NAME.csv``, ``NAME.html``, ``NAME/``):
a rename replaces a link rather than writing where it points, and a reader sees
either the old file or the new one whole, never a file being written.

So two recordings of the same name never write into each other's files: one
stopping while another (``overwrite``) starts each finish complete, and the one
published last holds the names. ``links`` lists the final names that are
symbolic links: the desk refuses such a name (``LinkedName``).

A recording cut off by a kill leaves its private files behind, whole up to
their last flush (see docs/recording.md: the end states).
"""

from __future__ import annotations

import contextlib
import logging
import os
import secrets
import shutil
from pathlib import Path
from typing import TextIO

FINAL_SUFFIXES = (".txt", ".csv", ".html", "")
"""The names a recording takes: NAME.txt, NAME.csv, NAME.html and the bag folder NAME/."""
log = logging.getLogger("c2rviz.record")
_CREATE = os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW | os.O_CLOEXEC


def links(folder: Path, name: str) -> list[Path]:
    """The final names of ``name`` in ``folder`` that are symbolic links."""
    return [p for p in _finals(folder, name) if p.is_symlink()]


def existing(folder: Path, name: str) -> list[Path]:
    """The final names of ``name`` in ``folder`` that exist (a dangling link counts)."""
    return [p for p in _finals(folder, name) if os.path.lexists(p)]


def is_bag_folder(path: Path, name: str) -> bool:
    """Whether the folder ``path`` holds a recording's bag ``name`` and nothing else (so it
    may be replaced), or nothing at all."""
    allowed = {"metadata.yaml", f"{name}.mcap", ".c2rviz-reserve"}
    try:
        with os.scandir(path) as entries:
            return all(e.name in allowed and e.is_file(follow_symlinks=False) for e in entries)
    except OSError:
        return False


def _finals(folder: Path, name: str) -> list[Path]:
    return [folder / f"{name}{suffix}" for suffix in FINAL_SUFFIXES]


class RecordFiles:
    """The private and the final names of one recording's files, in one folder."""

    def __init__(self, folder: Path, name: str) -> None:
        """Names for recording ``name`` into ``folder`` (nothing is created yet)."""
        self.folder = folder
        self.name = name
        self.stem = f".{name}.{secrets.token_hex(4)}"

    def private(self, suffix: str) -> Path:
        """The private name of the file ending in ``suffix`` (``.csv``, ``.txt.part``...)."""
        return self.folder / f"{self.stem}{suffix}"

    def final(self, suffix: str) -> Path:
        """The name a file ending in ``suffix`` takes when published (``""``: the bag)."""
        return self.folder / f"{self.name}{suffix}"

    def create(self, suffix: str) -> int:
        """Create the private file for ``suffix``, new (never an existing one or a link);
        return its descriptor, open for writing.

        Raises:
            OSError: it exists, or cannot be created.
        """
        return os.open(self.private(suffix), _CREATE, 0o644)

    def open_text(self, suffix: str, buffering: int) -> TextIO:
        """``create``, as ASCII text with a write buffer of ``buffering`` bytes."""
        fd = self.create(suffix)
        try:
            return open(fd, "w", buffering=buffering, encoding="ascii")  # noqa: SIM115
        except BaseException:
            os.close(fd)
            raise

    @property
    def bag_parent(self) -> Path:
        """The private folder the bag is written in."""
        return self.private(".bag")

    def bag_folder(self) -> Path:
        """Make the private folder and return where the bag folder goes in it (``NAME``).

        Raises:
            OSError: it cannot be made (or something is there already).
        """
        os.mkdir(self.bag_parent, 0o755)
        return self.bag_parent / self.name

    def publish(self, private: Path) -> Path:
        """Rename the private file ``private`` into its final name (its suffix after the
        stem: ``.TOKEN.csv`` -> ``NAME.csv``); return the final path.

        Raises:
            OSError: the rename failed (the private file stays).
        """
        suffix = private.name.removeprefix(self.stem)
        final = self.final(suffix.removesuffix(".part"))
        os.replace(private, final)
        return final

    def publish_bag(self) -> Path:
        """Put the bag folder in its final place ``NAME/``, replacing what was there.

        A bag already there (an earlier recording, ``overwrite``) is moved aside under
        a private name first, then deleted; a folder holding anything else is moved
        aside and kept (``.NAME.TOKEN.old``, with a warning); a file or link there is
        removed (a link itself, never what it points to).

        Raises:
            OSError: the bag cannot be moved there.
        """
        final = self.final("")
        aside = self.private(".old")
        if final.is_symlink() or final.is_file():
            final.unlink()
        elif final.is_dir():
            os.rename(final, aside)
        os.rename(self.bag_parent / self.name, final)
        with contextlib.suppress(OSError):
            os.rmdir(self.bag_parent)
        if aside.is_dir() and is_bag_folder(aside, self.name):
            shutil.rmtree(aside, ignore_errors=True)
        elif aside.exists():
            log.warning("%s held more than a bag: it is kept as %s", final, aside)
        return final

    def discard(self, *suffixes: str) -> None:
        """Remove private files that will not be published (errors ignored)."""
        for suffix in suffixes:
            with contextlib.suppress(OSError):
                self.private(suffix).unlink()


def join_body(fd: int, header: str, body: Path, chunk_bytes: int) -> None:
    """Write ``header`` then ``body``'s bytes up to its last newline to the new file ``fd``
    (closed after), reading ``chunk_bytes`` at a time (memory stays flat).

    Raises:
        OSError: a read or a write failed.
    """
    with (
        open(fd, "wb") as out,
        open(os.open(body, os.O_RDONLY | os.O_NOFOLLOW | os.O_CLOEXEC), "rb") as source,
    ):
        out.write(header.encode("ascii"))
        tail = b""
        while chunk := source.read(chunk_bytes):
            chunk = tail + chunk
            cut = chunk.rfind(b"\n") + 1
            out.write(chunk[:cut])
            tail = chunk[cut:]


def cut_to_line(path: Path) -> None:
    """Cut ``path`` after its last newline (a line cut short by a write error goes)."""
    fd = os.open(path, os.O_RDWR | os.O_NOFOLLOW | os.O_CLOEXEC)
    with open(fd, "r+b") as file:
        end = file.seek(0, os.SEEK_END)
        at = end
        while at > 0:
            start = max(0, at - 65536)
            file.seek(start)
            block = file.read(at - start)
            newline = block.rfind(b"\n")
            if newline >= 0:
                at = start + newline + 1
                break
            at = start
        if at < end:
            file.truncate(at)


def body_tally(path: Path, chunk_bytes: int = 1 << 16) -> tuple[int, int]:
    """What a recorder's command-file body at ``path`` holds: its frames and its time [us].

    A frame is a ``joints`` line, except the one a ``clear`` writes right after itself
    (the arm put back where it is) once the first frame is written; the time is the sum
    of its ``sleep`` lines. Read ``chunk_bytes`` at a time (memory stays flat).

    Raises:
        OSError: it cannot be read.
    """
    frames = us = 0
    after_clear = False
    tail = b""
    with open(os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_CLOEXEC), "rb") as source:
        while chunk := source.read(chunk_bytes):
            *lines, tail = (tail + chunk).split(b"\n")
            for line in lines:
                if line.startswith(b"joints ") and not (after_clear and frames):
                    frames += 1
                elif line.startswith(b"sleep "):
                    us += round(float(line[6:]) * 1e6)
                after_clear = line == b"clear"
    return frames, us
