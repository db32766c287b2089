"""Where a robot description comes from: its URDF text and its mesh files.

``load_source`` reads a URDF (expanding a ``.xacro`` first, with
``xacro.expand_xacro``) into a ``RobotSource``; the source resolves every mesh
reference in it to a file on disk, the way ROS would but without ROS:

- ``package://NAME/rest`` looks for package NAME, in this order: in each
  ``--package-path`` entry (``NAME=DIR`` names the folder outright; a plain
  ``DIR`` is the package itself, holds ``DIR/NAME``, or holds it further down
  with a ``package.xml`` that says ``<name>NAME</name>``), then the same in each
  ``ROS_PACKAGE_PATH`` entry, then ``PREFIX/share/NAME`` for each
  ``AMENT_PREFIX_PATH`` prefix, then upward from the URDF's folder: a folder
  named NAME (with or without a ``package.xml``) or one whose ``package.xml``
  names it.
- ``file://PATH`` and plain paths; relative ones against the URDF's folder.

Kinematics never need the meshes, so a mesh that cannot be found is not an
error here: ``searched`` and ``missing_meshes`` say where it was looked for, and
the viewer warns with that and draws a stand-in.
"""

from __future__ import annotations

import os
import re
import xml.etree.ElementTree as ET
from collections import deque
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from urllib.parse import unquote

from ..errors import ConfigError, RobotError
from .xacro import expand_xacro, parse_xacro_args

MAX_URDF_BYTES = 16 << 20
"""Longest robot description (the URDF, or a xacro file's expansion) [bytes]."""
MAX_JOINTS = 128
"""Most joints in a robot description (a two-armed robot with hands has about 60; a
128-joint chain takes about 400 MB with its page and collision model, 500 took 7 GB)."""
MAX_LINKS = MAX_JOINTS + 1
"""Most links in a robot description (a tree has one link more than joints)."""
MAX_MESH_BYTES = 256 << 20
"""Most bytes of mesh files a robot's description may name, all together."""

_NAME = re.compile(r"<name>\s*([^<\s]+)\s*</name>")
_LINK_TAG = re.compile(r"<link[\s/>]")
_JOINT_TAG = re.compile(r"<joint[\s/>]")
_MESH = re.compile(r"""<mesh\b[^>]*\bfilename\s*=\s*["']([^"']+)["']""")
_PACKAGE_NAME = re.compile(r"[A-Za-z0-9_.-]+")
_SCAN_DEPTH = 4  # how far below a package-path entry package.xml files are looked for
_SCAN_MAX_DIRS = 5000  # and how many folders at most, so a too-wide entry stays quick
_IGNORE_MARKERS = ("CATKIN_IGNORE", "COLCON_IGNORE", "AMENT_IGNORE")
# The first element of an XML text, past a BOM, the declaration, comments and a doctype.
_ROOT_TAG = re.compile(
    r"\ufeff?\s*(?:(?:<\?.*?\?>|<!--.*?-->|<!DOCTYPE[^>]*>)\s*)*<([A-Za-z_][\w:.-]*)", re.DOTALL
)


def package_name(folder: Path) -> str | None:
    """The ``<name>`` in ``folder/package.xml``, or None if there is none."""
    try:
        text = (folder / "package.xml").read_text(encoding="utf-8", errors="replace")
    except OSError:
        return None
    match = _NAME.search(text)
    return match.group(1) if match else None


def _scan_packages(root: Path) -> dict[str, list[Path]]:
    """Packages at or below ``root`` (by ``package.xml``), as rospack crawls them."""
    found: dict[str, list[Path]] = {}
    queue = deque([(root, 0)])
    visited = 0
    while queue and visited < _SCAN_MAX_DIRS:
        folder, depth = queue.popleft()
        visited += 1
        name = package_name(folder)
        if name is not None:
            found.setdefault(name, []).append(folder)
            continue  # packages do not nest
        if depth >= _SCAN_DEPTH or any((folder / m).exists() for m in _IGNORE_MARKERS):
            continue
        try:
            children = sorted(p for p in folder.iterdir() if p.is_dir())
        except OSError:
            continue
        queue.extend((c, depth + 1) for c in children if not c.name.startswith("."))
    return found


@dataclass(frozen=True)
class MissingMesh:
    """A mesh reference that resolves to no file.

    Attributes:
        uri: The ``filename`` as written in the URDF.
        links: The links whose visual or collision geometry uses it.
        searched: Every file path that was tried, in order.
    """

    uri: str
    links: tuple[str, ...]
    searched: tuple[Path, ...]

    def message(self) -> str:
        """The warning text: the file, its links and the places searched."""
        links = ", ".join(self.links)
        where = (
            ", ".join(str(p) for p in self.searched) or "nowhere (remote meshes are not fetched)"
        )
        hint = ""
        if self.uri.startswith("package://"):
            name = self.uri[len("package://") :].partition("/")[0]
            hint = f" (give the folder that holds {name} with --package-path DIR)"
        return f"mesh {self.uri} of link {links} not found; searched: {where}{hint}"


@dataclass(frozen=True)
class RobotSource:
    """A URDF's text and the places its meshes are looked up in.

    Attributes:
        xml: The URDF text (already expanded if it came from a ``.xacro``).
        path: The file it was read from (None for text given directly).
        package_paths: ``--package-path`` folders, in search order.
        package_map: ``--package-path NAME=DIR`` entries: package NAME is DIR.
        ros_package_path: ``ROS_PACKAGE_PATH`` entries when the source was loaded.
        ament_prefix_path: ``AMENT_PREFIX_PATH`` prefixes when the source was loaded.
    """

    xml: str
    path: Path | None = None
    package_paths: tuple[Path, ...] = ()
    package_map: tuple[tuple[str, Path], ...] = ()
    ros_package_path: tuple[Path, ...] = ()
    ament_prefix_path: tuple[Path, ...] = ()
    _scans: dict[Path, dict[str, list[Path]]] = field(
        default_factory=dict, init=False, repr=False, compare=False
    )

    @property
    def folder(self) -> Path:
        return self.path.parent if self.path is not None else Path.cwd()

    def _packages_under(self, root: Path) -> dict[str, list[Path]]:
        if root not in self._scans:
            self._scans[root] = _scan_packages(root) if root.is_dir() else {}
        return self._scans[root]

    def package_dirs(self, name: str) -> list[Path]:
        """Candidate folders for package ``name``, in search order (existing or not)."""
        candidates = [folder for key, folder in self.package_map if key == name]
        for root in (*self.package_paths, *self.ros_package_path):
            if root.name == name:
                candidates.append(root)
            candidates.append(root / name)
            candidates.extend(self._packages_under(root).get(name, []))
        candidates.extend(prefix / "share" / name for prefix in self.ament_prefix_path)
        for parent in [self.folder, *self.folder.parents]:
            if parent.name == name or package_name(parent) == name:
                candidates.append(parent)
            candidates.append(parent / name)
        return list(dict.fromkeys(candidates))  # drop repeats, keep the order

    def find_package(self, name: str) -> Path | None:
        """The first existing folder for package ``name`` (what ``$(find NAME)`` gives)."""
        return next((d for d in self.package_dirs(name) if d.is_dir()), None)

    def searched(self, uri: str) -> list[Path]:
        """Every file ``resolve(uri)`` tries, in order; empty for remote URIs."""
        if uri.startswith("package://"):
            name, _, rest = uri[len("package://") :].partition("/")
            return [folder / rest for folder in self.package_dirs(name)]
        if uri.startswith(("http://", "https://")):
            return []
        path = Path(unquote(uri[len("file://") :]) if uri.startswith("file://") else uri)
        return [path if path.is_absolute() else self.folder / path]

    def resolve(self, uri: str) -> Path | None:
        """The file a mesh reference names, or None when it is nowhere to be found."""
        return next((p for p in self.searched(uri) if p.is_file()), None)

    def mesh_uris(self) -> dict[str, tuple[str, ...]]:
        """Each mesh ``filename`` in the URDF, with the links that use it."""
        try:
            root = ET.fromstring(self.xml)
        except ET.ParseError:  # Pinocchio's parser forgives more than ElementTree does
            return {uri: ("?",) for uri in dict.fromkeys(_MESH.findall(self.xml))}
        uses: dict[str, list[str]] = {}
        for link in root.iter("link"):
            for mesh in link.iter("mesh"):
                uri = mesh.get("filename")
                if uri:
                    users = uses.setdefault(uri, [])
                    if link.get("name", "?") not in users:
                        users.append(link.get("name", "?"))
        return {uri: tuple(links) for uri, links in uses.items()}

    def missing_meshes(self) -> list[MissingMesh]:
        """The meshes that resolve to no file, each with the places searched."""
        return [
            MissingMesh(uri, links, tuple(self.searched(uri)))
            for uri, links in self.mesh_uris().items()
            if self.resolve(uri) is None
        ]


def split_package_path(
    entry: str | Path, relative_to: Path | None = None
) -> tuple[str | None, Path]:
    """One package search entry, as (package name or None, absolute folder).

    ``NAME=DIR`` says package NAME is the folder DIR; any other entry is a DIR to
    search (so is a ``NAME=DIR`` text that exists as a folder itself). The same
    forms serve ``--package-path`` and the ini's ``package_path``.

    Args:
        entry: ``DIR`` or ``NAME=DIR``; ``~`` is expanded.
        relative_to: The folder a relative DIR is taken from (the ini file's
            folder for the ini; default: the working directory).
    """
    base = Path.cwd() if relative_to is None else relative_to
    text = str(entry)
    name, sep, named = text.partition("=")
    if sep and _PACKAGE_NAME.fullmatch(name) and not (base / Path(text).expanduser()).exists():
        return name, (base / Path(named).expanduser()).resolve()
    return None, (base / Path(text).expanduser()).resolve()


def check_urdf_root(xml: str, where: Path) -> None:
    """Raise RobotError unless ``xml``'s root element is ``<robot>``.

    Checked before Pinocchio sees the text: urdfdom, under Pinocchio, prints
    its own complaint about a missing ``robot`` element straight to stderr.

    Args:
        xml: The description text.
        where: The file it came from, for the message.
    """
    match = _ROOT_TAG.match(xml)
    if match is None:
        raise RobotError(f"{where} is not a URDF: it is not XML (a URDF starts with <robot ...>)")
    tag = match.group(1)
    if tag != "robot":
        what = " (an SDF file: c2rviz reads URDF and xacro)" if tag == "sdf" else ""
        raise RobotError(f"{where} is not a URDF: its root element is <{tag}>, not <robot>{what}")


def check_size(source: RobotSource, where: Path) -> None:
    """Raise RobotError, in one sentence, for a description past the documented limits
    (``MAX_URDF_BYTES``, ``MAX_LINKS``, ``MAX_JOINTS``, ``MAX_MESH_BYTES``): checked before
    any model is built, since a model of thousands of links takes gigabytes."""
    xml = source.xml
    if len(xml) > MAX_URDF_BYTES:
        raise RobotError(
            f"{where} is {len(xml) / 2**20:.1f} MiB of robot description, over the limit "
            f"of {MAX_URDF_BYTES >> 20} MiB"
        )
    for what, pattern, most in (
        ("links", _LINK_TAG, MAX_LINKS),
        ("joints", _JOINT_TAG, MAX_JOINTS),
    ):
        count = len(pattern.findall(xml))
        if count > most:
            raise RobotError(f"{where} has {count} {what}, over the limit of {most}")
    problem = _tree_problem(xml)
    if problem is not None:
        raise RobotError(f"{where} is not a tree of links: {problem}")
    total = 0
    for uri in source.mesh_uris():
        found = source.resolve(uri)
        if found is not None:
            try:
                total += found.stat().st_size
            except OSError:
                continue
    if total > MAX_MESH_BYTES:
        raise RobotError(
            f"{where} names {total:,} bytes of mesh files, over the limit of "
            f"{MAX_MESH_BYTES:,} ({MAX_MESH_BYTES >> 20} MiB)"
        )


def _tree_problem(xml: str) -> str | None:
    """Why the joints of ``xml`` do not make a tree (a link with two parents, a cycle), in
    words, or None (urdfdom says only "no root link found")."""
    try:
        root = ET.fromstring(xml)
    except ET.ParseError:
        return None  # Pinocchio's parser says what is wrong with the XML itself
    parent: dict[str, tuple[str, str]] = {}  # child link -> (parent link, joint)
    for joint in root.iter("joint"):
        above, below = joint.find("parent"), joint.find("child")
        if above is None or below is None:
            continue
        name, child = joint.get("name", "?"), below.get("link", "?")
        if child in parent:
            return f"link {child!r} is the child of two joints ({parent[child][1]!r} and {name!r})"
        parent[child] = (above.get("link", "?"), name)
    for start in parent:
        seen = [start]
        link = start
        while link in parent:
            link = parent[link][0]
            if link == start:
                through = ", ".join(parent[a][1] for a in seen)
                return f"its joints form a cycle: link {start!r} is its own ancestor ({through})"
            if link in seen:
                break  # a cycle that does not pass through start: found from its own links
            seen.append(link)
    return None


def _split_env(value: str | None) -> tuple[Path, ...]:
    return tuple(Path(p) for p in (value or "").split(os.pathsep) if p)


def load_source(
    path: str | Path,
    package_paths: Sequence[str | Path] = (),
    xacro_args: Mapping[str, str] | Iterable[str] = (),
    *,
    environ: Mapping[str, str] | None = None,
) -> RobotSource:
    """Read the URDF at ``path``, expanding it with xacro if it ends in ``.xacro``.

    Args:
        path: A ``.urdf`` or ``.xacro`` file.
        package_paths: ``--package-path`` entries: ``DIR`` or ``NAME=DIR``.
        xacro_args: ``name:=value`` strings (or a mapping) for xacro's ``$(arg name)``.
        environ: Where ``ROS_PACKAGE_PATH`` and ``AMENT_PREFIX_PATH`` are read
            (default ``os.environ``).

    Raises:
        RobotError: the file does not exist, cannot be read, does not expand or is
            not a URDF (its root element is not ``<robot>``).
        ConfigError: a package path that is not a folder, or a bad xacro argument.
    """
    path = Path(path)
    if not path.is_file():
        raise RobotError(f"URDF file {str(path)!r} does not exist")
    env = os.environ if environ is None else environ
    folders: list[Path] = []
    mapped: list[tuple[str, Path]] = []
    for entry in package_paths:
        name, folder = split_package_path(entry)
        if not folder.is_dir():
            named = f" (for package {name})" if name is not None else ""
            raise ConfigError(f"--package-path {str(folder)!r}{named} is not a folder")
        if name is None:
            folders.append(folder)
        else:
            mapped.append((name, folder))
    resolved = path.resolve()
    source = RobotSource(
        "",
        resolved,
        tuple(folders),
        tuple(mapped),
        _split_env(env.get("ROS_PACKAGE_PATH")),
        _split_env(env.get("AMENT_PREFIX_PATH")),
    )
    args = parse_xacro_args(xacro_args)
    if path.suffix == ".xacro":
        xml = expand_xacro(resolved, args, source.find_package)
    else:
        if args:
            raise ConfigError(f"--xacro-arg given, but {path} is not a .xacro file")
        try:
            xml = path.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError) as exc:
            raise RobotError(f"cannot read {path}: {exc}") from exc
    check_urdf_root(xml, path)
    scans = source._scans
    source = replace(source, xml=xml)
    source._scans.update(scans)  # keep the package.xml scans made while expanding
    check_size(source, path)
    return source
