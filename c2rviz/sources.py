"""Where a robot description comes from: its URDF text and its mesh files.

``load_source`` reads a URDF file into a ``RobotSource``; the source resolves
every mesh reference in it (``package://NAME/...``, ``file://...`` or a path
relative to the URDF's folder) to a file on disk. Kinematics never need the
meshes, so a mesh that cannot be found is the viewer's concern, not an error.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from .errors import RobotError

__all__ = ["RobotSource", "load_source"]


@dataclass(frozen=True)
class RobotSource:
    """A URDF's text and the places its meshes are looked up in.

    Attributes:
        xml: The URDF text.
        path: The file it was read from (None for text given directly).
        package_paths: Folders searched for ``package://NAME`` (NAME is a
            sub-folder of one of them).
    """

    xml: str
    path: Path | None = None
    package_paths: tuple[Path, ...] = ()

    @property
    def folder(self) -> Path:
        return self.path.parent if self.path is not None else Path.cwd()

    def package_dirs(self, name: str) -> list[Path]:
        """Candidate folders for package ``name``, in search order."""
        candidates = [root / name for root in self.package_paths]
        for parent in [self.folder, *self.folder.parents]:
            if parent.name == name:
                candidates.append(parent)
            candidates.append(parent / name)
        return candidates

    def resolve(self, uri: str) -> Path | None:
        """The file a mesh reference names, or None when it is nowhere to be found."""
        if uri.startswith("package://"):
            name, _, rest = uri[len("package://") :].partition("/")
            for folder in self.package_dirs(name):
                if (folder / rest).is_file():
                    return folder / rest
            return None
        path = Path(uri[len("file://") :] if uri.startswith("file://") else uri)
        path = path if path.is_absolute() else self.folder / path
        return path if path.is_file() else None


def load_source(path: str | Path, package_paths: Sequence[str | Path] = ()) -> RobotSource:
    """Read the URDF at ``path``.

    Raises:
        RobotError: the file does not exist or cannot be read.
    """
    path = Path(path)
    if not path.is_file():
        raise RobotError(f"URDF file {str(path)!r} does not exist")
    try:
        xml = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise RobotError(f"cannot read {path}: {exc}") from exc
    return RobotSource(xml, path.resolve(), tuple(Path(p) for p in package_paths))
