"""The URDF's visual and collision elements as ``robot.visuals`` reads them are what yourdfpy
reads (the library the program used before, kept as the judge) on every bundled robot,
every example robot and the test robots; a hostile document expands nothing."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import pytest
import yourdfpy

from c2rviz.robot.catalogue import example_robot_data_dir, example_robots
from c2rviz.robot.visuals import Element, read_links

ROOT = Path(__file__).resolve().parents[2]
FILES = sorted((ROOT / "robots").glob("*/robot.urdf")) + sorted(
    (ROOT / "tests" / "data").rglob("*.urdf")
)
EXAMPLES = sorted(example_robots()) if example_robot_data_dir() is not None else []


def _same_element(ours: Element, theirs: yourdfpy.Visual | yourdfpy.Collision, rgba) -> None:
    want_origin = theirs.origin if theirs.origin is not None else np.eye(4)
    assert np.allclose(ours.origin, want_origin, atol=1e-12)
    geom = theirs.geometry
    kinds = [k for k in ("box", "cylinder", "sphere", "mesh") if getattr(geom, k) is not None]
    assert ours.geometry is not None and [ours.geometry.kind] == kinds
    if geom.box is not None:
        assert ours.geometry.size == tuple(float(v) for v in geom.box.size)
    elif geom.cylinder is not None:
        assert ours.geometry.size == (geom.cylinder.radius, geom.cylinder.length)
    elif geom.sphere is not None:
        assert ours.geometry.size == (geom.sphere.radius,)
    else:
        assert ours.geometry.filename == geom.mesh.filename
        if geom.mesh.scale is None:
            assert ours.geometry.scale is None
        else:
            assert np.allclose(ours.geometry.scale, geom.mesh.scale)
    assert rgba == _their_rgba(theirs)


def _their_rgba(element):
    material = getattr(element, "material", None)
    if material is None:
        return None
    color = material.color
    if color is None and material.name in _their_rgba.materials:
        color = _their_rgba.materials[material.name].color
    return None if color is None else tuple(float(c) for c in color.rgba)


def check_against_yourdfpy(xml: str) -> int:
    """Compare every link's elements; returns how many elements were compared."""
    theirs = yourdfpy.URDF.load(
        io.BytesIO(xml.encode()), build_scene_graph=False, load_meshes=False
    ).robot
    _their_rgba.materials = {m.name: m for m in theirs.materials if m.name is not None}
    ours = read_links(xml)
    assert list(ours.visuals) == [link.name for link in theirs.links]
    compared = 0
    for link in theirs.links:
        assert len(ours.visuals[link.name]) == len(link.visuals), link.name
        assert len(ours.collisions[link.name]) == len(link.collisions), link.name
        for mine, their in zip(ours.visuals[link.name], link.visuals, strict=True):
            _same_element(mine, their, ours.rgba(mine))
            compared += 1
        for mine, their in zip(ours.collisions[link.name], link.collisions, strict=True):
            _same_element(mine, their, None)
            compared += 1
    return compared


@pytest.mark.parametrize("path", FILES, ids=lambda p: str(p.relative_to(ROOT)))
def test_bundled_and_test_robots_read_as_yourdfpy_reads_them(path: Path) -> None:
    assert check_against_yourdfpy(path.read_text()) > 0


@pytest.mark.parametrize("name", EXAMPLES)
def test_example_robots_read_as_yourdfpy_reads_them(name: str) -> None:
    assert check_against_yourdfpy(example_robots()[name].urdf.read_text()) > 0


def test_materials_by_name_scale_and_origins_as_urdf_writes_them() -> None:
    xml = """<robot name="r">
      <material name="blue"><color rgba="0 0 1 1"/></material>
      <link name="a">
        <visual><origin xyz="1 2 3" rpy="0.1 0.2 0.3"/>
          <geometry><mesh filename="package://p/m.stl" scale="2 2 2"/></geometry>
          <material name="blue"/></visual>
        <visual><geometry><cylinder radius="0.1" length="0.5"/></geometry>
          <material name="own"><color rgba="1 0 0 0.5"/></material></visual>
        <collision><geometry><sphere radius="0.2"/></geometry></collision>
      </link>
      <link name="b"/>
    </robot>"""
    assert check_against_yourdfpy(xml) == 3
    links = read_links(xml)
    mesh, cylinder = links.visuals["a"]
    assert links.rgba(mesh) == (0.0, 0.0, 1.0, 1.0) and links.rgba(cylinder) == (1, 0, 0, 0.5)
    assert mesh.geometry is not None and list(mesh.geometry.scale) == [2.0, 2.0, 2.0]
    assert links.visuals["b"] == [] and links.collisions["b"] == []


def test_entities_are_never_expanded() -> None:
    levels = ['<!ENTITY a0 "aaaaaaaaaa">'] + [
        f'<!ENTITY a{k} "{f"&a{k - 1};" * 10}">' for k in range(1, 9)
    ]
    xml = (
        f'<?xml version="1.0"?><!DOCTYPE robot [{"".join(levels)}]>'
        '<robot name="r"><link name="&a8;"><visual><geometry><box size="1 1 1"/></geometry>'
        '<material name="&a8;"/></visual></link></robot>'
    )
    links = read_links(xml)
    assert all(len(name) < 1000 for name in links.visuals)
    for elements in links.visuals.values():
        assert all(e.material is None or len(e.material) < 1000 for e in elements)
