"""Robots, scenes and an independent collision check for the planning tests.

The independent check does not use ``CollisionModel`` or ``ValidityChecker``:
it reads the URDF's ``<collision>`` geometry with Pinocchio (meshes as they
are, not their convex hulls) and asks coal, pair by pair, with exact requests.
Its self pairs are its own rule: links with geometry not joined by a joint
and apart at home, at the start and at the goal (structural contacts out).
"""

from __future__ import annotations

import importlib.metadata
from collections.abc import Sequence
from dataclasses import dataclass
from functools import cache
from itertools import combinations
from pathlib import Path

import coal
import numpy as np
import pinocchio as pin

from c2rviz.collision import CollisionModel
from c2rviz.robot import Robot

ROOT = Path(__file__).resolve().parents[2]
BUNDLED = {
    "motoman_sia20d": ("robots/motoman_sia20d/robot.urdf", "base_link", "link_t"),
    "fanuc_lrmate200id": ("robots/fanuc_lrmate200id/robot.urdf", "base_link", "link_6"),
    "kuka_lwr": ("robots/kuka_lwr/robot.urdf", "lwr_base_link", "lwr_7_link"),
}
BOX_M = 0.15  # [m] edge of the box put in the way


def erd_folder() -> Path | None:
    """example-robot-data's package folder (holding ``robots/``), or None."""
    try:
        dist = importlib.metadata.distribution("example-robot-data")
    except importlib.metadata.PackageNotFoundError:
        return None
    for file in dist.files or ():
        if file.parts[-2:] == ("example-robot-data", "package.xml"):
            return Path(str(dist.locate_file(file))).parent
    return None


def urdf_of(name: str) -> tuple[Path, str, str, list[Path]]:
    """The URDF, base link, end link and package folders of a bundled arm or the panda."""
    if name == "panda":
        folder = erd_folder()
        assert folder is not None
        urdf = folder / "robots/panda_description/urdf/panda.urdf"
        return urdf, "panda_link0", "panda_hand_tcp", [folder.parent]
    path, base, eelink = BUNDLED[name]
    return ROOT / path, base, eelink, []


@cache
def load(name: str) -> Robot:
    urdf, base, eelink, packages = urdf_of(name)
    return Robot.from_urdf(urdf, base, eelink, package_paths=packages)


@dataclass(frozen=True)
class Scene:
    """A start, a goal and the boxes (size, centre in the base frame) [rad or m]."""

    start: tuple[float, ...]
    goal: tuple[float, ...]
    boxes: tuple[tuple[tuple[float, float, float], tuple[float, float, float]], ...]


def furnish(model: CollisionModel, scene: Scene) -> None:
    model.remove_all()
    for k, (size, centre) in enumerate(scene.boxes):
        model.set_object(f"box{k}", "box", size, pin.SE3(np.eye(3), np.array(centre)))


def blocked_scenes(model: CollisionModel, count: int, seed: int, reach: float = 1.2) -> list[Scene]:
    """Scenes whose straight joint path meets a box put where the tool passes halfway."""
    robot = model.robot
    rng = np.random.default_rng(seed)
    found: list[Scene] = []
    while len(found) < count:
        model.remove_all()
        start = np.array(model.random_free(rng))
        goal = np.clip(start + rng.uniform(-reach, reach, robot.n), robot.lower, robot.upper)
        centre = robot.ee_pose(((start + goal) / 2).tolist()).translation
        scene = Scene(tuple(start), tuple(goal), (((BOX_M,) * 3, tuple(centre)),))
        furnish(model, scene)
        path = [start + f * (goal - start) for f in np.linspace(0, 1, 200)]
        if model.is_free(list(start)) and model.is_free(list(goal)) and model.first_collision(path):
            found.append(scene)
    return found


class IndependentCheck:
    """Pinocchio + coal straight from the URDF: is a configuration free of the boxes and itself?"""

    def __init__(self, name: str, scene: Scene) -> None:
        robot = load(name)
        urdf, _, _, packages = urdf_of(name)
        self.robot = robot
        self.model = robot.model
        self.data = robot.model.createData()
        self.geometry = pin.buildGeomFromUrdf(
            robot.model, str(urdf), pin.COLLISION, package_dirs=[str(p) for p in packages]
        )
        self.gdata = self.geometry.createData()
        base = robot.base_placement
        self.boxes = []
        for size, centre in scene.boxes:
            where = base * pin.SE3(np.eye(3), np.array(centre))
            self.boxes.append(
                (coal.Box(*size), coal.Transform3s(where.rotation, where.translation))
            )
        objects = self.geometry.geometryObjects
        # A bounding sphere per shape, exact arithmetic only: shapes whose spheres are apart
        # cannot touch, so coal is asked only about the rest (the same answers, sooner).
        for shape in [obj.geometry for obj in objects] + [box for box, _ in self.boxes]:
            shape.computeLocalAABB()
        self._centre = np.array([obj.geometry.aabb_center for obj in objects])
        self._radius = np.array([obj.geometry.aabb_radius for obj in objects]) + 1e-9
        self._box_centre = [np.array(where.getTranslation()) for _, where in self.boxes]
        self._box_radius = [box.aabb_radius for box, _ in self.boxes]
        joined = {(self.model.parents[a.parentJoint], a.parentJoint) for a in objects} | {
            (a.parentJoint, self.model.parents[a.parentJoint]) for a in objects
        }
        candidates = [
            (i, j)
            for i, j in combinations(range(len(objects)), 2)
            if objects[i].parentJoint != objects[j].parentJoint
            and (objects[i].parentJoint, objects[j].parentJoint) not in joined
        ]
        apart_everywhere = set(candidates)
        for q in (robot.home, scene.start, scene.goal):
            self._place(q)
            apart_everywhere -= {pair for pair in candidates if self._touch(*pair)}
        self.self_pairs = sorted(apart_everywhere)
        self._pairs = np.array(self.self_pairs, dtype=int).reshape(-1, 2)

    def _place(self, q: Sequence[float]) -> None:
        config = self.robot.configuration(q)
        pin.updateGeometryPlacements(self.model, self.data, self.geometry, self.gdata, config)
        self._shapes = [obj.geometry for obj in self.geometry.geometryObjects]
        self._where = [coal.Transform3s(m.rotation, m.translation) for m in self.gdata.oMg]
        rotations = np.array([m.rotation for m in self.gdata.oMg])
        translations = np.array([m.translation for m in self.gdata.oMg])
        self._world = np.einsum("nij,nj->ni", rotations, self._centre) + translations

    def _touch(self, i: int, j: int) -> bool:
        return _collide(self._shapes[i], self._where[i], self._shapes[j], self._where[j])

    def hits(self, q: Sequence[float]) -> list[str]:
        """What ``q`` [rad or m] touches: ``link/box k`` and ``link/link`` names."""
        self._place(q)
        names = [obj.name for obj in self.geometry.geometryObjects]
        found = []
        for k, (box, where) in enumerate(self.boxes):
            gap = np.linalg.norm(self._world - self._box_centre[k], axis=1)
            near = np.flatnonzero(gap <= self._radius + self._box_radius[k])
            found += [
                f"{names[i]}/box{k}"
                for i in near
                if _collide(self._shapes[i], self._where[i], box, where)
            ]
        first, second = self._pairs[:, 0], self._pairs[:, 1]
        gap = np.linalg.norm(self._world[first] - self._world[second], axis=1)
        near = self._pairs[gap <= self._radius[first] + self._radius[second]]
        found += [f"{names[i]}/{names[j]}" for i, j in near.tolist() if self._touch(i, j)]
        return found


_REQUEST = coal.CollisionRequest()
_REQUEST.enable_contact = True  # run GJK to its end: no early "apart" on shallow contacts


def _collide(
    a: coal.CollisionGeometry, pa: coal.Transform3s, b: coal.CollisionGeometry, pb: coal.Transform3s
) -> bool:
    return bool(coal.collide(a, pa, b, pb, _REQUEST, coal.CollisionResult()))


def polyline_samples(waypoints: np.ndarray, step_rad: float) -> np.ndarray:
    """Points along the polyline, no joint moving more than ``step_rad`` between two."""
    points = [waypoints[:1]]
    for a, b in zip(waypoints[:-1], waypoints[1:]):
        count = max(1, int(np.ceil(np.max(np.abs(b - a)) / step_rad)))
        points.append(a + np.linspace(0, 1, count + 1)[1:, None] * (b - a))
    return np.vstack(points)


def distance_to_polyline(qs: np.ndarray, waypoints: np.ndarray) -> np.ndarray:
    """Euclidean distance [rad or m] from each row of ``qs`` to the nearest point of the
    polyline (one array op per edge, not a Python loop per sample)."""
    qs = np.atleast_2d(np.asarray(qs, dtype=float))
    best = np.full(len(qs), np.inf)
    for a, b in zip(waypoints[:-1], waypoints[1:]):
        d = b - a
        f = np.clip((qs - a) @ d / max(float(np.dot(d, d)), 1e-300), 0.0, 1.0)
        best = np.minimum(best, np.linalg.norm(qs - (a + f[:, None] * d), axis=1))
    return best
