"""A mesh read from a file: triangles, and the file's own colour (``mesh_files``, ``collada``)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Mesh", "MeshFileError"]


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
