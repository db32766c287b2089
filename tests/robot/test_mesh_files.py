"""STL and OBJ read with numpy alone (issue 39, rough edge 12): the same triangles as trimesh
reads from the same files (trimesh is the judge here), and a robot of such meshes builds its
geometry without importing trimesh, which took half a second of the page's start."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import trimesh
from support import ROOT

from c2rviz.robot.mesh_files import Mesh, MeshFileError, read_mesh

DATA = ROOT / "tests" / "data"
FILES = [
    DATA / "tree_robot" / "meshes" / "hand.stl",
    DATA / "tiny_ws" / "src" / "tiny_description" / "meshes" / "link.stl",
    DATA / "tiny_ws" / "src" / "gripper-checkout" / "meshes" / "finger.stl",
    DATA / "mtl_robot" / "part.obj",
]


def triangles(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Every triangle as its three corners, in a canonical order (rotation kept: winding)."""
    corners = np.asarray(vertices)[np.asarray(faces)]  # (m, 3, 3)
    out = []  # each triangle rotated to start at its least corner
    for tri in corners:
        k = min(range(3), key=lambda i: tuple(tri[i]))
        out.append(np.roll(tri, -k, axis=0).ravel())
    return np.array(sorted(map(tuple, np.round(out, 9))))


def judge(path: Path) -> list[trimesh.Trimesh]:
    scene = trimesh.load_scene(str(path))
    return [g for g in scene.dump() if isinstance(g, trimesh.Trimesh)]


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.name)
def test_the_test_robots_meshes_read_as_trimesh_reads_them(path: Path) -> None:
    ours, theirs = read_mesh(path), judge(path)
    assert len(ours) == len(theirs)
    for mine, judged in zip(ours, theirs):
        assert len(mine.vertices) == len(judged.vertices)  # an STL's shared corners merged
        np.testing.assert_array_equal(
            triangles(mine.vertices, mine.faces), triangles(judged.vertices, judged.faces)
        )


@pytest.mark.parametrize("kind", ["binary", "ascii"])
def test_an_stl_either_way_is_the_mesh_written(kind: str, tmp_path: Path) -> None:
    made = trimesh.creation.icosphere(subdivisions=2, radius=0.07)
    made.apply_translation((0.1, -0.2, 0.3))
    path = tmp_path / f"ball.{kind}.STL"
    path.write_bytes(trimesh.exchange.stl.export_stl(made) if kind == "binary" else
                     trimesh.exchange.stl.export_stl_ascii(made).encode())  # fmt: skip
    (mesh,) = read_mesh(path)
    judged = trimesh.Trimesh(mesh.vertices, mesh.faces, process=False)
    assert judged.is_watertight and judged.is_winding_consistent
    assert judged.volume == pytest.approx(made.volume, rel=1e-5)
    np.testing.assert_allclose(mesh.extents, made.extents, rtol=1e-6)
    assert mesh.rgba is None  # an STL has no colour of its own
    np.testing.assert_allclose(mesh.scaled(np.array([2.0, 1.0, 1.0])).extents[0], 0.28, rtol=1e-5)


def test_an_obj_keeps_its_materials_colour_and_its_polygons(tmp_path: Path) -> None:
    (tmp_path / "two.mtl").write_text("newmtl red\nKd 1 0 0\nd 0.5\nnewmtl grey\nKd 0.5 0.5 0.5\n")
    (tmp_path / "two.obj").write_text(
        "mtllib two.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\n"
        "usemtl red\nf 1/1/1 2/2/2 3/3/3 4/4/4\nusemtl grey\nf -5//1 -4//1 -1//1\n"
    )
    red, grey = read_mesh(tmp_path / "two.obj")
    assert red.rgba == (1.0, 0.0, 0.0, 0.5) and grey.rgba == (0.5, 0.5, 0.5, 1.0)
    assert red.faces.tolist() == [[0, 1, 2], [0, 2, 3]]  # the square as a fan of two
    assert grey.vertices.tolist() == [[0, 0, 0], [1, 0, 0], [0, 0, 1]]


@pytest.mark.parametrize(
    ("name", "data"),
    [("empty.stl", b""), ("short.stl", b"solid x\nendsolid x\n"), ("nan.obj", b"v nan 0 0\n")],
)
def test_what_it_cannot_read_it_says(name: str, data: bytes, tmp_path: Path) -> None:
    (tmp_path / name).write_bytes(data)
    with pytest.raises(MeshFileError):
        read_mesh(tmp_path / name)


BUILD = """
import sys
from c2rviz.robot.model import Robot
from c2rviz.robot.visuals import load_link_geometry
for urdf in sys.argv[1:]:
    robot = Robot.from_urdf(urdf, eelink="tool0" if "tree" in urdf else None)
    links = load_link_geometry(robot.source)
    meshes = [s.mesh for g in links.values() for s in g.visual if s.mesh is not None]
    print(urdf, len(meshes), sorted({type(m).__name__ for m in meshes}))
print("trimesh loaded:", "trimesh" in sys.modules)
"""


def test_a_robot_of_stl_and_obj_meshes_builds_without_trimesh() -> None:
    urdfs = [DATA / "tree_robot" / "tree.urdf", DATA / "mtl_robot" / "robot.urdf"]
    done = subprocess.run(
        [sys.executable, "-c", BUILD, *map(str, urdfs)],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    assert "trimesh loaded: False" in done.stdout, done.stdout
    assert done.stdout.count(f"['{Mesh.__name__}']") == 2, done.stdout
