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

    def _place(self, q: Sequence[float]) -> None:
        config = self.robot.configuration(q)
        pin.updateGeometryPlacements(self.model, self.data, self.geometry, self.gdata, config)
        self._shapes = [obj.geometry for obj in self.geometry.geometryObjects]
        self._where = [coal.Transform3s(m.rotation, m.translation) for m in self.gdata.oMg]

    def _touch(self, i: int, j: int) -> bool:
        return _collide(self._shapes[i], self._where[i], self._shapes[j], self._where[j])

    def hits(self, q: Sequence[float]) -> list[str]:
        """What ``q`` [rad or m] touches: ``link/box k`` and ``link/link`` names."""
        self._place(q)
        names = [obj.name for obj in self.geometry.geometryObjects]
        found = [
            f"{names[i]}/box{k}"
            for k, (box, where) in enumerate(self.boxes)
            for i in range(len(names))
            if _collide(self._shapes[i], self._where[i], box, where)
        ]
        found += [f"{names[i]}/{names[j]}" for i, j in self.self_pairs if self._touch(i, j)]
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


def distance_to_polyline(q: np.ndarray, waypoints: np.ndarray) -> float:
    """Euclidean distance [rad or m] from ``q`` to the nearest point of the polyline."""
    best = np.inf
    for a, b in zip(waypoints[:-1], waypoints[1:]):
        d = b - a
        f = float(np.clip(np.dot(q - a, d) / max(np.dot(d, d), 1e-300), 0.0, 1.0))
        best = min(best, float(np.linalg.norm(q - (a + f * d))))
    return best
