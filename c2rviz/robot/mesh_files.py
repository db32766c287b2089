"""STL, OBJ and COLLADA mesh files read with numpy (trimesh takes half a second to import).

A robot's page is built at the program's start, so reading its mesh files must not pay for
a mesh library: ``read_mesh`` reads the formats robot descriptions use most, STL (binary
or ASCII), Wavefront OBJ (its ``.mtl`` diffuse colours, one piece per material) and
COLLADA ``.dae`` (``read_collada``, below: one piece per primitive and placement, in its
material's diffuse colour), into ``Mesh`` pieces; ``visuals`` hands any other format
(``.ply``, glTF ...), and a file these readers refuse (a texture, say), to trimesh,
imported then. As trimesh does, an STL's corners shared by several triangles become one
vertex (so the page shades it smooth), and an OBJ keeps its own vertices.
``tests/robot/test_mesh_files.py`` holds both to trimesh's reading of the same files. A
``Mesh``: triangles, and the file's own colour.

COLLADA ``.dae`` meshes are read with lxml and numpy. What robot descriptions' ``.dae``
files hold: ``<triangles>`` and ``<polylist>`` of ``<geometry>`` meshes, placed by the
``<node>`` tree of the scene (``<matrix>``, ``<translate>``, ``<rotate>``, ``<scale>``),
each piece in its material's diffuse colour. One ``Mesh`` per piece and placement, its
corners moved by the node's transform and shared corners merged. Anything else (a texture,
``<polygons>`` with holes, an ``<instance_node>``, a controller) raises ``MeshFileError``,
and trimesh reads the file as before. The XML is parsed with entities, the network and
DTDs off.
"""

from __future__ import annotations

import math
import os
import re
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from lxml import etree


class MeshFileError(ValueError):
    """A mesh file this reader cannot read (trimesh then tries it)."""


@dataclass(frozen=True, eq=False)
class Mesh:
    """Triangles: ``vertices`` (k, 3) [m, after scale], ``faces`` (m, 3) indices into them,
    and the file's own colour ``rgba`` (a material's diffuse; None: the file has none)."""

    vertices: np.ndarray
    faces: np.ndarray
    rgba: tuple[float, float, float, float] | None = None

    @property
    def extents(self) -> np.ndarray:
        """The size of its bounding box along x, y, z."""
        return np.ptp(self.vertices, axis=0) if len(self.vertices) else np.zeros(3)

    def scaled(self, factors: np.ndarray) -> Mesh:
        """The same mesh with each axis scaled by ``factors`` (3,)."""
        return Mesh(self.vertices * np.asarray(factors, dtype=float), self.faces, self.rgba)


def read_collada(data: bytes) -> list[Mesh]:
    """The pieces of the COLLADA document ``data``, placed as its scene places them.

    Raises:
        MeshFileError: it holds what this reader does not (trimesh then reads it).
    """
    parser = etree.XMLParser(
        resolve_entities=False, no_network=True, load_dtd=False, huge_tree=True
    )
    try:
        root = etree.fromstring(data, parser=parser)
    except etree.XMLSyntaxError as exc:
        raise MeshFileError(f"not XML: {exc}") from None
    ids = {node.get("id"): node for node in root.iter() if node.get("id")}
    scene = root.find("{*}scene/{*}instance_visual_scene")
    if scene is None:
        raise MeshFileError("no scene")
    pieces = []
    for geometry, place, bound in _instances(_target(ids, scene.get("url")), np.eye(4), ids):
        for primitive in _mesh_of(geometry):
            positions, keys = _corners(primitive, ids)
            colour = _colour(bound.get(primitive.get("material") or ""), ids)
            # a corner is its position and its normal: where the file gives a corner two
            # normals (a hard edge), it stays two vertices, as trimesh keeps them
            unique, first, index = np.unique(keys, axis=0, return_index=True, return_inverse=True)
            del unique
            vertices = positions[first] @ place[:3, :3].T + place[:3, 3]
            pieces.append(Mesh(vertices, index.reshape(-1, 3).astype(np.int64), colour))
    return pieces


def _target(ids: dict[str | None, etree._Element], url: str | None) -> etree._Element:
    if not url or not url.startswith("#") or url[1:] not in ids:
        raise MeshFileError(f"a reference to {url!r} that is not in the file")
    return ids[url[1:]]


def _instances(
    node: etree._Element, parent: np.ndarray, ids: dict[str | None, etree._Element]
) -> Iterator[tuple[etree._Element, np.ndarray, dict[str, str]]]:
    """Each geometry the node tree places: the geometry, its placement, its materials."""
    for child in node:
        tag = etree.QName(child).localname
        if tag == "node":
            yield from _instances(child, parent @ _transform(child), ids)
        elif tag == "instance_geometry":
            bound = {
                m.get("symbol", ""): m.get("target", "")
                for m in child.iterfind(".//{*}instance_material")
            }
            yield _target(ids, child.get("url")), parent, bound
        elif tag in ("instance_node", "instance_controller"):
            raise MeshFileError(f"<{tag}> is not read here")


def _transform(node: etree._Element) -> np.ndarray:
    """A node's own transform: its transform elements, in order."""
    out = np.eye(4)
    for child in node:
        tag = etree.QName(child).localname
        values = [float(v) for v in (child.text or "").split()] if tag in _TRANSFORMS else []
        if tag == "matrix" and len(values) == 16:
            step = np.array(values).reshape(4, 4)
        elif tag == "translate" and len(values) == 3:
            step = np.eye(4)
            step[:3, 3] = values
        elif tag == "scale" and len(values) == 3:
            step = np.diag([*values, 1.0])
        elif tag == "rotate" and len(values) == 4:
            step = _rotation(np.array(values[:3]), math.radians(values[3]))
        elif tag in _TRANSFORMS:
            raise MeshFileError(f"a <{tag}> of {len(values)} numbers")
        else:
            continue
        out = out @ step
    return out


_TRANSFORMS = ("matrix", "translate", "scale", "rotate", "lookat", "skew")


def _rotation(axis: np.ndarray, angle: float) -> np.ndarray:
    norm = float(np.linalg.norm(axis))
    out = np.eye(4)
    if norm == 0.0:
        return out
    x, y, z = axis / norm
    c, s = math.cos(angle), math.sin(angle)
    out[:3, :3] = [
        [c + x * x * (1 - c), x * y * (1 - c) - z * s, x * z * (1 - c) + y * s],
        [y * x * (1 - c) + z * s, c + y * y * (1 - c), y * z * (1 - c) - x * s],
        [z * x * (1 - c) - y * s, z * y * (1 - c) + x * s, c + z * z * (1 - c)],
    ]
    return out


def _mesh_of(geometry: etree._Element) -> list[etree._Element]:
    mesh = geometry.find("{*}mesh")
    if mesh is None:
        raise MeshFileError("a geometry that is not a mesh")
    out = []
    for primitive in mesh:
        tag = etree.QName(primitive).localname
        if tag in ("triangles", "polylist"):
            out.append(primitive)
        elif tag in ("polygons", "trifans", "tristrips"):  # lines are not drawn: skipped
            raise MeshFileError(f"<{tag}> is not read here")
    return out


def _corners(
    primitive: etree._Element, ids: dict[str | None, etree._Element]
) -> tuple[np.ndarray, np.ndarray]:
    """The triangles' corners of a ``<triangles>`` or ``<polylist>``: their positions
    (3k, 3) and what tells two corners apart (3k, 2): the position's and the normal's
    indices (-1: no normal)."""
    inputs = primitive.findall("{*}input")
    stride = 1 + max((int(i.get("offset", "0")) for i in inputs), default=0)
    vertex = next((i for i in inputs if i.get("semantic") == "VERTEX"), None)
    if vertex is None:
        raise MeshFileError("a primitive without VERTEX")
    positions = _positions(_target(ids, vertex.get("source")), ids)
    p = primitive.find("{*}p")
    index = np.array((p.text or "").split() if p is not None else [], dtype=np.int64)
    if len(index) % stride:
        raise MeshFileError("a <p> that does not fill its inputs")
    normal = next((i for i in inputs if i.get("semantic") == "NORMAL"), None)
    rows = index.reshape(-1, stride)
    corners = rows[:, int(vertex.get("offset", "0"))]
    normals = rows[:, int(normal.get("offset", "0"))] if normal is not None else corners * 0 - 1
    if etree.QName(primitive).localname == "polylist":
        counts = primitive.find("{*}vcount")
        sizes = np.array((counts.text or "").split() if counts is not None else [], dtype=np.int64)
        if sizes.sum() != len(corners) or (sizes < 3).any():
            raise MeshFileError("a <vcount> that does not match <p>")
        starts = np.concatenate([[0], np.cumsum(sizes)[:-1]])
        fans = [
            (s, s + k, s + k + 1)
            for s, n in zip(starts.tolist(), sizes.tolist())
            for k in range(1, n - 1)
        ]
        order = np.array(fans, dtype=np.int64).reshape(-1)
        corners, normals = corners[order], normals[order]
    elif len(corners) % 3:
        raise MeshFileError("<triangles> whose corners are not in threes")
    if len(corners) and (corners.min() < 0 or corners.max() >= len(positions)):
        raise MeshFileError("a corner names a position that is not there")
    return positions[corners], np.stack([corners, normals], axis=1)


def _positions(vertices: etree._Element, ids: dict[str | None, etree._Element]) -> np.ndarray:
    position = next(
        (i for i in vertices.iterfind("{*}input") if i.get("semantic") == "POSITION"), None
    )
    if position is None:
        raise MeshFileError("<vertices> without POSITION")
    source = _target(ids, position.get("source"))
    array = source.find("{*}float_array")
    accessor = source.find("{*}technique_common/{*}accessor")
    if array is None or accessor is None:
        raise MeshFileError("a source without float_array or accessor")
    values = np.array((array.text or "").split(), dtype=float)
    stride = int(accessor.get("stride", "1"))
    count = int(accessor.get("count", "0"))
    offset = int(accessor.get("offset", "0"))
    if stride < 3 or offset + count * stride > len(values) or not np.all(np.isfinite(values)):
        raise MeshFileError("positions that are not x, y, z numbers")
    return values[offset : offset + count * stride].reshape(count, stride)[:, :3]


def _colour(
    target: str | None, ids: dict[str | None, etree._Element]
) -> tuple[float, float, float, float] | None:
    """A material's diffuse colour (None: no material); a texture is not read here."""
    if not target:
        return None
    material = _target(ids, target)
    effect_at = material.find("{*}instance_effect")
    effect = _target(ids, effect_at.get("url") if effect_at is not None else None)
    diffuse = effect.find(".//{*}technique/*/{*}diffuse")
    if diffuse is None:
        return None
    if diffuse.find("{*}color") is None:
        raise MeshFileError("a diffuse that is not a colour (a texture)")
    values = [float(v) for v in (diffuse.find("{*}color").text or "").split()]
    if len(values) < 3:
        raise MeshFileError("a colour of fewer than three numbers")
    r, g, b, a = (min(max(v, 0.0), 1.0) for v in [*values[:3], *values[3:4], 1.0][:4])
    return (r, g, b, a)


FORMATS = (".stl", ".obj", ".dae")
"""The suffixes read here (any case); others go to trimesh."""
_MAX_BYTES = 512 * 1024 * 1024  # a mesh file this big is refused (trimesh is asked)


def read_mesh(path: Path) -> list[Mesh]:
    """The pieces of the STL or OBJ file at ``path`` (one, or one per OBJ material).

    Raises:
        MeshFileError: the file is not one this reader understands.
        OSError: it cannot be read.
    """
    suffix = path.suffix.lower()
    if suffix not in FORMATS:
        raise MeshFileError(f"{path.name}: not {' or '.join(FORMATS)}")
    if os.path.getsize(path) > _MAX_BYTES:
        raise MeshFileError(f"{path.name}: larger than {_MAX_BYTES} bytes")
    data = path.read_bytes()
    if suffix == ".dae":
        pieces = read_collada(data)
    else:
        pieces = _stl(data) if suffix == ".stl" else _obj(data, path.parent)
    pieces = [p for p in pieces if len(p.faces)]
    if not pieces:
        raise MeshFileError(f"{path.name}: no triangles")
    return pieces


def _stl(data: bytes) -> list[Mesh]:
    if len(data) >= 84:
        count = int.from_bytes(data[80:84], "little")
        if 84 + 50 * count == len(data):  # binary: 50 bytes a triangle
            record = np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")])
            corners = np.frombuffer(data, record, count, 84)["v"].reshape(-1, 3)
            return [merged(corners.astype(float))]
    if not data.lstrip()[:5].lower() == b"solid":
        raise MeshFileError("neither a binary STL nor an ASCII one")
    numbers = re.findall(rb"^\s*vertex\s+(\S+)\s+(\S+)\s+(\S+)", data, re.MULTILINE)
    if not numbers or len(numbers) % 3:
        raise MeshFileError("an ASCII STL whose facets are not triangles")
    return [merged(np.array(numbers, dtype=float))]


def merged(corners: np.ndarray) -> Mesh:
    """Triangles given corner by corner (3k, 3), each distinct corner one vertex."""
    if not np.all(np.isfinite(corners)):
        raise MeshFileError("a corner is not a finite number")
    vertices, index = np.unique(corners, axis=0, return_inverse=True)
    return Mesh(vertices, index.reshape(-1, 3).astype(np.int64))


def _obj(data: bytes, folder: Path) -> list[Mesh]:
    vertices: list[list[float]] = []
    faces: dict[str | None, list[list[int]]] = {}
    material: str | None = None
    colours: dict[str, tuple[float, float, float, float]] = {}
    for raw in data.splitlines():
        words = raw.split(b"#", 1)[0].split()
        if not words:
            continue
        key = words[0]
        if key == b"v":
            vertices.append([float(w) for w in words[1:4]])
        elif key == b"f":
            k = len(vertices)
            corners = [_obj_index(w, k) for w in words[1:]]
            fan = range(1, len(corners) - 1)  # a polygon: a fan of triangles from its first
            faces.setdefault(material, []).extend(
                [corners[0], corners[i], corners[i + 1]] for i in fan
            )
        elif key == b"usemtl":
            material = words[1].decode("utf-8", "replace") if len(words) > 1 else None
        elif key == b"mtllib":
            for lib in words[1:]:
                colours.update(_mtl(folder / lib.decode("utf-8", "replace")))
    points = np.array(vertices, dtype=float).reshape(-1, 3)
    if not np.all(np.isfinite(points)):
        raise MeshFileError("a vertex is not a finite number")
    pieces = []
    for name, triangles in faces.items():
        index = np.array(triangles, dtype=np.int64).reshape(-1, 3)
        if len(index) and (index.min() < 0 or index.max() >= len(points)):
            raise MeshFileError("a face names a vertex that is not there")
        used, local = np.unique(index, return_inverse=True)
        colour = colours.get(name) if name is not None else None
        pieces.append(Mesh(points[used], local.reshape(-1, 3), colour))
    return pieces


def _obj_index(word: bytes, count: int) -> int:
    """A face corner's vertex index (``v``, ``v/vt``, ``v//vn``, ``v/vt/vn``; 1-based, or
    negative from the end), 0-based."""
    index = int(word.split(b"/", 1)[0])
    return index - 1 if index > 0 else count + index


def _mtl(path: Path) -> dict[str, tuple[float, float, float, float]]:
    """Each material's diffuse colour (``Kd``) and opacity (``d``) in a ``.mtl`` file."""
    try:
        text = path.read_bytes()
    except OSError:
        return {}
    out: dict[str, tuple[float, float, float, float]] = {}
    name: str | None = None
    rgb, alpha = (1.0, 1.0, 1.0), 1.0
    for raw in [*text.splitlines(), b"newmtl"]:  # the last one ends at the end
        words = raw.split(b"#", 1)[0].split()
        if not words:
            continue
        if words[0] == b"newmtl":
            if name is not None:
                out[name] = (*rgb, alpha)
            name = words[1].decode("utf-8", "replace") if len(words) > 1 else None
            rgb, alpha = (1.0, 1.0, 1.0), 1.0
        elif words[0] == b"Kd" and len(words) >= 4:
            r, g, b = (min(max(float(w), 0.0), 1.0) for w in words[1:4])
            rgb = (r, g, b)
        elif words[0] == b"d" and len(words) >= 2:
            alpha = min(max(float(words[1]), 0.0), 1.0)
    return out
