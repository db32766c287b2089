"""COLLADA ``.dae`` meshes read with lxml and numpy (as ``mesh_files`` reads STL and OBJ).

What robot descriptions' ``.dae`` files hold: ``<triangles>`` and ``<polylist>`` of
``<geometry>`` meshes, placed by the ``<node>`` tree of the scene (``<matrix>``,
``<translate>``, ``<rotate>``, ``<scale>``), each piece in its material's diffuse colour.
One ``Mesh`` per piece and placement, its corners moved by the node's transform and
shared corners merged. Anything else (a texture, ``<polygons>`` with holes, an
``<instance_node>``, a controller) raises ``MeshFileError``, and trimesh reads the
file as before. The XML is parsed with entities, the network and DTDs off.
"""

from __future__ import annotations

import math
from collections.abc import Iterator

import numpy as np
from lxml import etree

from .mesh import Mesh, MeshFileError

__all__ = ["read_collada"]


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
