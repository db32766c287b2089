"""The marker meshes made with numpy are trimesh's ``creation`` shapes of the same sizes:
closed, outward-facing, the same volume, extent and area (trimesh is the judge here)."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from c2rviz.protocol.grammar import MARKER_SHAPES
from c2rviz.view.markers import MARKER_SIZE_M, marker_mesh


def trimesh_marker(shape: str, size: float = MARKER_SIZE_M) -> trimesh.Trimesh:
    """The page's markers as they were made with trimesh before."""
    if shape == "cube":
        return trimesh.creation.box(extents=(size, size, size))
    if shape == "cylinder":
        return trimesh.creation.cylinder(radius=size / 3, height=size, sections=24)
    if shape == "arrow":
        head = size / 2
        shaft_length = 1.7 * size - head
        shaft = trimesh.creation.cylinder(radius=size / 8, height=shaft_length, sections=16)
        shaft.apply_translation((0.0, 0.0, shaft_length / 2))
        cone = trimesh.creation.cone(radius=size / 3, height=head, sections=16)
        cone.apply_translation((0.0, 0.0, shaft_length))
        arrow = trimesh.util.concatenate([shaft, cone])
        arrow.apply_transform(trimesh.transformations.rotation_matrix(np.pi / 2, (0, 1, 0)))
        return arrow
    return trimesh.creation.icosphere(subdivisions=2, radius=size / 2)


@pytest.mark.parametrize("shape", MARKER_SHAPES)
def test_each_marker_is_the_shape_trimesh_made(shape: str) -> None:
    vertices, faces = marker_mesh(shape)
    ours = trimesh.Trimesh(vertices, faces, process=False)
    theirs = trimesh_marker(shape)
    pieces = ours.split(only_watertight=False)
    assert len(pieces) == (2 if shape == "arrow" else 1)
    for piece in pieces:
        assert piece.is_watertight and piece.is_winding_consistent
        assert piece.volume > 0  # outward normals: a positive signed volume
    assert np.allclose(ours.bounds, theirs.bounds, atol=1e-12)
    assert ours.volume == pytest.approx(theirs.volume, rel=1e-9)
    assert ours.area == pytest.approx(theirs.area, rel=1e-9)
    assert len(faces) == len(theirs.faces)
