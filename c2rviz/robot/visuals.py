"""What each link looks like: URDF visual and collision geometry, ready to draw.

``read_links`` (below) reads the URDF (links, their ``<visual>``/``<collision>``
elements and materials); ``load_link_geometry`` turns every element into a ``Shape`` placed
at its URDF origin in the link frame. Boxes, cylinders and spheres stay
primitives (the viewer draws them natively); mesh files, resolved through
``RobotSource.resolve``, are read by ``mesh_files`` when they are STL, OBJ or COLLADA
(numpy and lxml: building the page pays for no mesh library) and by trimesh otherwise
(imported at the first such file: most robots never load it). Link poses are not
computed here: the viewer takes them from Pinocchio.

A mesh that cannot be found or read is logged with the places searched, and
the link falls back to its collision geometry or, failing that, a small grey
placeholder, so a robot with missing meshes is still drawn and never crashes
the program.

The URDF's ``<visual>`` and ``<collision>`` elements of each link, as plain values
(``UrdfLinks``), are what is drawn from: each element's origin in its link's frame, its
geometry (box, cylinder, sphere, or a mesh file and its scale) and, for a visual, its
material. Read with lxml, hardened as everywhere (no entities resolved, no network, no
DTD); nothing is loaded: a mesh is only its file name here.

Read here rather than by yourdfpy, which reads the same elements but imports trimesh,
scipy and networkx with it (half of the program's start, for robots drawn from boxes and
cylinders); ``tests/robot/test_urdf_elements.py`` holds the two readers equal on every
bundled and example robot.
"""

from __future__ import annotations

import logging
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from lxml import etree

from .mesh_files import FORMATS, Mesh, MeshFileError, read_mesh
from .sources import RobotSource

if TYPE_CHECKING:
    import trimesh


@dataclass(frozen=True)
class Geometry:
    """One ``<geometry>``: ``kind`` is box, cylinder, sphere or mesh.

    Attributes:
        size: Box edges (x, y, z) [m]; cylinder (radius, length) [m]; sphere (radius,) [m].
        filename: A mesh's file reference, as the URDF writes it.
        scale: A mesh's scale (one value or three), None when not given.
    """

    kind: str
    size: tuple[float, ...] = ()
    filename: str = ""
    scale: np.ndarray | None = None


@dataclass(frozen=True)
class Element:
    """One ``<visual>`` or ``<collision>`` of a link.

    Attributes:
        origin: 4x4 pose in the link's frame (the URDF ``<origin>``).
        geometry: What it is; None when the element has no geometry URDF knows.
        material: The material's name (a visual's; may name a top-level material).
        rgba: The material's own colour, if the element gives one.
    """

    origin: np.ndarray
    geometry: Geometry | None
    material: str | None = None
    rgba: tuple[float, float, float, float] | None = None


@dataclass
class UrdfLinks:
    """Every link's elements, in the file's order, and the top-level materials' colours."""

    visuals: dict[str, list[Element]] = field(default_factory=dict)
    collisions: dict[str, list[Element]] = field(default_factory=dict)
    materials: dict[str, tuple[float, float, float, float]] = field(default_factory=dict)

    def rgba(self, element: Element) -> tuple[float, float, float, float] | None:
        """The colour ``element``'s material gives, directly or through a top-level one."""
        if element.rgba is not None:
            return element.rgba
        return self.materials.get(element.material) if element.material else None


def read_links(xml: str) -> UrdfLinks:
    """The links' elements of the URDF text ``xml`` (see the module docstring)."""
    parser = etree.XMLParser(  # one per call: an lxml parser is not for two threads at once
        resolve_entities=False, no_network=True, load_dtd=False, huge_tree=False, recover=True
    )
    root = etree.fromstring(xml.encode("utf-8"), parser=parser)
    links = UrdfLinks()
    if root is None:
        return links
    for material in root.findall("material"):
        rgba = _color(material)
        if material.get("name") and rgba is not None:
            links.materials[material.get("name")] = rgba
    for link in root.findall("link"):
        name = link.get("name", "")
        links.visuals[name] = [_element(e, visual=True) for e in link.findall("visual")]
        links.collisions[name] = [_element(e, visual=False) for e in link.findall("collision")]
    return links


def _element(node: etree._Element, visual: bool) -> Element:
    material = node.find("material") if visual else None
    return Element(
        _origin(node.find("origin")),
        _geometry(node.find("geometry")),
        material.get("name") if material is not None else None,
        _color(material) if material is not None else None,
    )


def _floats(text: str | None, default: tuple[float, ...]) -> tuple[float, ...]:
    return tuple(float(v) for v in text.split()) if text and text.split() else default


def _color(node: etree._Element) -> tuple[float, float, float, float] | None:
    color = node.find("color")
    if color is None or color.get("rgba") is None:
        return None
    try:
        r, g, b, a = _floats(color.get("rgba"), ())
    except ValueError:  # not four numbers: no colour
        return None
    return (r, g, b, a)


def _origin(node: etree._Element | None) -> np.ndarray:
    """The 4x4 pose of an ``<origin xyz rpy>`` (roll, pitch, yaw about the fixed x, y, z)."""
    pose = np.eye(4)
    if node is None:
        return pose
    roll, pitch, yaw = _floats(node.get("rpy"), (0.0, 0.0, 0.0))
    cr, sr, cp, sp = np.cos(roll), np.sin(roll), np.cos(pitch), np.sin(pitch)
    cy, sy = np.cos(yaw), np.sin(yaw)
    pose[:3, :3] = [
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
        [-sp, cp * sr, cp * cr],
    ]
    pose[:3, 3] = _floats(node.get("xyz"), (0.0, 0.0, 0.0))
    return pose


def _geometry(node: etree._Element | None) -> Geometry | None:
    """The geometry, or None (none given, or numbers that are not: nothing to draw)."""
    try:
        return _shape(node)
    except (TypeError, ValueError):
        return None


def _shape(node: etree._Element | None) -> Geometry | None:
    if node is None:
        return None
    for shape in node:
        if shape.tag == "box":
            return Geometry("box", _floats(shape.get("size"), (0.0, 0.0, 0.0)))
        if shape.tag == "cylinder":
            return Geometry("cylinder", (float(shape.get("radius")), float(shape.get("length"))))
        if shape.tag == "sphere":
            return Geometry("sphere", (float(shape.get("radius")),))
        if shape.tag == "mesh":
            scale = shape.get("scale")
            factors = np.array(_floats(scale, ())) if scale is not None else None
            return Geometry("mesh", filename=shape.get("filename", ""), scale=factors)
    return None


log = logging.getLogger("c2rviz.visuals")

DEFAULT_RGBA = (0.7, 0.7, 0.72, 1.0)  # URDF geometry without a material colour
COLLISION_RGBA = (1.0, 0.45, 0.1, 0.45)  # translucent orange, as RViz draws collisions
PLACEHOLDER_SIZE_M = 0.05


@dataclass(frozen=True)
class Shape:
    """One drawable piece of a link, in the link frame.

    Attributes:
        kind: ``box``, ``cylinder``, ``sphere`` or ``mesh``.
        origin: 4x4 pose of the piece in its link's frame (the URDF ``<origin>``).
        rgba: Colour, each channel 0..1. For a mesh: the URDF ``<material>``
            colour when its ``<visual>`` gives one (it wins over the mesh
            file's own colours and textures, such as an ``.obj``'s ``.mtl``);
            else None when the file brings colours of its own (they are kept);
            else the default grey.
        size: Box edge lengths (x, y, z) [m]; cylinder (radius, length) [m];
            sphere (radius,) [m]; empty for a mesh.
        mesh: The loaded mesh (kind ``mesh`` only), scale already applied: a
            ``mesh_files.Mesh`` (STL, OBJ) or a trimesh one (any other format).
    """

    kind: str
    origin: np.ndarray
    rgba: tuple[float, float, float, float] | None
    size: tuple[float, ...] = ()
    mesh: Mesh | trimesh.Trimesh | None = None


@dataclass
class LinkGeometry:
    """Everything drawn for one link.

    Attributes:
        visual: What the page shows normally.
        collision: What the 'collision geometry' checkbox shows.
        missing: Mesh references of this link that could not be loaded.
    """

    visual: list[Shape] = field(default_factory=list)
    collision: list[Shape] = field(default_factory=list)
    missing: list[str] = field(default_factory=list)


def load_link_geometry(source: RobotSource) -> dict[str, LinkGeometry]:
    """Every link's visual and collision shapes, keyed by link name.

    Never raises for a missing or broken mesh: see the module docstring.
    """
    urdf = read_links(source.xml)
    for missing in source.missing_meshes():  # each once, with its links and a hint
        log.warning("%s", missing.message())
    loader = _MeshLoader(source)
    links: dict[str, LinkGeometry] = {}
    for name, visuals in urdf.visuals.items():
        geometry = LinkGeometry()
        for element in visuals:
            shapes = _shapes(element, urdf.rgba(element), loader, geometry.missing)
            geometry.visual.extend(shapes)
        for element in urdf.collisions[name]:
            geometry.collision.extend(_shapes(element, COLLISION_RGBA, loader, []))
        if geometry.missing:
            _fall_back(name, geometry)
        links[name] = geometry
    return links


def _fall_back(link: str, geometry: LinkGeometry) -> None:
    """Stand in for the link's missing visual meshes."""
    if geometry.collision:
        stand_in = [
            Shape(s.kind, s.origin, DEFAULT_RGBA if s.kind != "mesh" else None, s.size, s.mesh)
            for s in geometry.collision
        ]
        how = "its collision geometry"
    else:
        size = (PLACEHOLDER_SIZE_M,) * 3
        stand_in = [Shape("box", np.eye(4), DEFAULT_RGBA, size)]
        how = "a placeholder box"
    geometry.visual.extend(stand_in)
    log.warning("link %s is drawn with %s instead of its missing mesh", link, how)


def _shapes(
    element: Element,
    rgba: tuple[float, float, float, float] | None,
    loader: _MeshLoader,
    missing: list[str],
) -> list[Shape]:
    """The shapes of one ``<visual>`` or ``<collision>`` element (none when a mesh is missing)."""
    origin, geom = element.origin, element.geometry
    if geom is None:
        return []
    if geom.kind != "mesh":
        return [Shape(geom.kind, origin, rgba or DEFAULT_RGBA, geom.size)]
    meshes = loader.load(geom.filename, geom.scale)
    if meshes is None:
        missing.append(geom.filename)
        return []
    shapes = []
    for mesh in meshes:
        # The URDF's colour is what the robot's author chose for this link, so it
        # wins over the file's (exporters often leave a near-white .mtl behind:
        # pybullet's kuka_iiwa). Without one, a file's own colours are kept.
        if isinstance(mesh, Mesh):
            own = mesh.rgba is not None
        else:
            own = mesh.visual is not None and mesh.visual.defined
        color = rgba if rgba is not None else None if own else DEFAULT_RGBA
        shapes.append(Shape("mesh", origin, color, (), mesh))
    return shapes


class _MeshLoader:
    """Loads mesh files once each, and says where it looked when it cannot."""

    def __init__(self, source: RobotSource) -> None:
        self.source = source
        self.cache: dict[str, list[Mesh | trimesh.Trimesh] | None] = {}

    def load(
        self, uri: str, scale: float | np.ndarray | None
    ) -> list[Mesh | trimesh.Trimesh] | None:
        """The pieces of the mesh file ``uri``, scaled; None when it cannot be loaded."""
        if uri not in self.cache:
            self.cache[uri] = self._read(uri)
        pieces = self.cache[uri]
        if pieces is None:
            return None
        if scale is None:
            return pieces
        factors = np.broadcast_to(np.asarray(scale, dtype=float), (3,))
        scaled: list[Mesh | trimesh.Trimesh] = []
        for piece in pieces:
            if isinstance(piece, Mesh):
                scaled.append(piece.scaled(factors))
                continue
            piece = piece.copy()
            piece.apply_transform(np.diag([*factors, 1.0]))
            scaled.append(piece)
        return scaled

    def _read(self, uri: str) -> list[Mesh | trimesh.Trimesh] | None:
        path = self.source.resolve(uri)
        if path is None:  # said already (load_link_geometry)
            return None
        if path.suffix.lower() in FORMATS:
            try:
                return list(read_mesh(path))
            except OSError as exc:
                log.warning("mesh %s (%s) cannot be read: %s", uri, path, exc.strerror or exc)
                return None
            except (MeshFileError, ValueError, IndexError) as exc:  # trimesh may know better
                log.debug("mesh %s: %s; trimesh reads it", path, exc)
        found = self._read_with_trimesh(uri, path)
        return None if found is None else list(found)

    def _read_with_trimesh(self, uri: str, path: Path) -> list[trimesh.Trimesh] | None:
        import trimesh  # the first such file: most robots never pay for it

        try:
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                scene = trimesh.load_scene(str(path))
                # dump() bakes each instance's transform; unlike
                # dump(concatenate=True) it keeps the pieces (and their
                # materials) apart and raises no DeprecationWarning.
                pieces = [g for g in scene.dump() if isinstance(g, trimesh.Trimesh)]
        except Exception as exc:  # trimesh raises many kinds for a bad file
            log.warning("mesh %s (%s) cannot be read: %s", uri, path, exc)
            return None
        for warning in caught:
            log.debug("loading %s: %s", path, warning.message)
        if not pieces:
            log.warning("mesh %s (%s) holds no triangles", uri, path)
            return None
        return pieces
