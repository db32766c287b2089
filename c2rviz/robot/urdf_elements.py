"""The URDF's ``<visual>`` and ``<collision>`` elements of each link, as plain values.

What ``visuals`` draws from: each element's origin in its link's frame, its geometry
(box, cylinder, sphere, or a mesh file and its scale) and, for a visual, its material.
Read with lxml, hardened as everywhere (no entities resolved, no network, no DTD);
nothing is loaded: a mesh is only its file name here.

Read here rather than by yourdfpy, which reads the same elements but imports trimesh,
scipy and networkx with it (half of the program's start, for robots drawn from boxes and
cylinders); ``tests/robot/test_urdf_elements.py`` holds the two readers equal on every
bundled and example robot.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from lxml import etree

__all__ = ["Element", "Geometry", "UrdfLinks", "read_links"]


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
