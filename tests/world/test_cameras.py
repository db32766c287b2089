"""The logical camera's rules: its frustum's edges, occlusion, poses in its frame, noise."""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest

from c2rviz.robot.frames import pose_se3, se3_pose
from c2rviz.world.cameras import (
    Camera,
    CameraError,
    Cameras,
    TooManyCameras,
    UnknownCamera,
    hidden,
    in_frustum,
    see,
)

EPS = 1e-6
H = math.tan(math.radians(30.0))  # the default h_fov's half, at x = 1
V = math.tan(math.radians(22.5))  # the default v_fov's half, at x = 1


def _camera(**kwargs: object) -> Camera:
    return Camera("cam", pin.SE3.Identity(), **kwargs)  # type: ignore[arg-type]


EDGES = [
    ((1.0, H - EPS, 0.0), True),
    ((1.0, H + EPS, 0.0), False),
    ((1.0, -H + EPS, 0.0), True),
    ((1.0, -H - EPS, 0.0), False),
    ((1.0, 0.0, V - EPS), True),
    ((1.0, 0.0, V + EPS), False),
    ((1.0, 0.0, -V + EPS), True),
    ((1.0, 0.0, -V - EPS), False),
    ((2.0 - EPS, 0.0, 0.0), True),
    ((2.0 + EPS, 0.0, 0.0), False),
    ((-1.0, 0.0, 0.0), False),
    ((0.0, 0.0, 0.0), False),
]


@pytest.mark.parametrize(
    ("point", "inside"),
    EDGES,
    ids=[
        "left-in",
        "left-out",
        "right-in",
        "right-out",
        "top-in",
        "top-out",
        "bottom-in",
        "bottom-out",
        "range-in",
        "range-out",
        "behind",
        "at-the-lens",
    ],
)
def test_frustum_edges(point: tuple[float, float, float], inside: bool) -> None:
    assert in_frustum(_camera(), np.array(point)) is inside


def test_frustum_follows_the_camera_pose_and_fov() -> None:
    # Looking straight down from 1 m (pitch +90 deg turns +x onto -z), 90 x 90 deg.
    camera = Camera("down", pose_se3((0, 0, 1, 0, math.pi / 2, 0)), math.pi / 2, math.pi / 2, 1.5)
    parts = [
        ("a", "battery", pose_se3((0.3, 0.0, 0.0, 0, 0, 0))),
        ("b", None, pose_se3((1.2, 0.0, 0.0, 0, 0, 0))),  # 50 deg off the axis
        ("c", None, pose_se3((0.0, 0.0, 1.5, 0, 0, 0))),  # above the camera
    ]
    seen = see(camera, parts, [], 0.0)
    assert [(s.name, s.kind) for s in seen] == [("a", "battery")]


def test_pose_in_the_camera_frame() -> None:
    camera = Camera("cam", pose_se3((1, 0, 1, 0, 0, math.pi / 2)))  # looking along world +y
    part = pose_se3((1, 1, 1, 0, 0, math.pi / 2))
    (seen,) = see(camera, [("p1", "battery", part)], [], 0.0)
    np.testing.assert_allclose(se3_pose(seen.pose), [1, 0, 0, 0, 0, 0], atol=1e-12)


@pytest.mark.parametrize(
    ("shape", "size", "at", "hides"),
    [
        ("box", (0.1, 0.1, 0.1), (0.5, 0, 0), True),
        ("box", (0.1, 0.1, 0.1), (0.5, 0.06, 0), False),
        ("sphere", (0.05,), (0.5, 0.049, 0), True),
        ("sphere", (0.05,), (0.5, 0.051, 0), False),
        ("cylinder", (0.05, 0.2), (0.5, 0, 0.09), True),
        ("cylinder", (0.05, 0.2), (0.5, 0, 0.11), False),
        ("box", (0.1, 0.1, 0.1), (1.5, 0, 0), False),  # behind the part
        ("box", (0.1, 0.1, 0.1), (-0.5, 0, 0), False),  # behind the camera
    ],
    ids=[
        "box",
        "box-beside",
        "sphere",
        "sphere-beside",
        "cylinder",
        "cylinder-below",
        "behind-part",
        "behind-camera",
    ],
)
def test_occlusion_by_an_object(
    shape: str, size: tuple[float, ...], at: tuple[float, float, float], hides: bool
) -> None:
    camera = _camera()
    occluder = ("wall", shape, size, pose_se3((*at, 0, 0, 0)))
    part = ("p1", None, pose_se3((1.0, 0, 0, 0, 0, 0)))
    assert (hidden(camera, np.array([1.0, 0, 0]), [occluder]) == "wall") is hides
    assert (see(camera, [part], [occluder], 0.0) == []) is hides


def test_a_turned_box_hides_by_its_own_axes() -> None:
    # A thin plate at x = 0.5, turned 90 deg about z: it now spans x, not y.
    plate = ("plate", "box", (0.01, 0.4, 0.4), pose_se3((0.5, 0, 0, 0, 0, math.pi / 2)))
    assert hidden(_camera(), np.array([1.0, 0, 0]), [plate]) == "plate"
    moved = ("plate", "box", (0.01, 0.4, 0.4), pose_se3((0.5, 0.1, 0, 0, 0, math.pi / 2)))
    assert hidden(_camera(), np.array([1.0, 0, 0]), [moved]) is None


def test_noise_repeats_with_the_seed() -> None:
    part = [("p1", None, pose_se3((1.0, 0, 0, 0, 0, 0)))]

    def run(seed: int) -> list[list[float]]:
        camera = _camera(sigma_m=0.01, sigma_rad=0.02, rng=np.random.default_rng(seed))
        return [list(se3_pose(see(camera, part, [], 0.0)[0].pose)) for _ in range(3)]

    assert run(7) == run(7)
    assert run(7) != run(8)
    first = run(7)
    assert first[0] != first[1]  # each look draws again
    assert all(abs(v - w) < 0.1 for v, w in zip(first[0][:3], [1, 0, 0]))


def test_a_look_without_noise_draws_nothing() -> None:
    part = [("p1", None, pose_se3((1.0, 0, 0, 0, 0, 0)))]
    camera = _camera(sigma_m=0.01, sigma_rad=0.02, rng=np.random.default_rng(5))
    exact = see(camera, part, [], 0.0, noisy=False)
    np.testing.assert_allclose(se3_pose(exact[0].pose), [1, 0, 0, 0, 0, 0], atol=1e-12)
    first = se3_pose(see(camera, part, [], 0.0)[0].pose)
    again = _camera(sigma_m=0.01, sigma_rad=0.02, rng=np.random.default_rng(5))
    assert se3_pose(see(again, part, [], 0.0)[0].pose) == first


def test_blackout_sees_nothing_until_its_time() -> None:
    cameras = Cameras()
    cameras.put(_camera())
    cameras.blackout("cam", 5.0)
    part = [("p1", None, pose_se3((1.0, 0, 0, 0, 0, 0)))]
    camera = cameras.get("cam")
    assert see(camera, part, [], 4.999) == []
    assert [s.name for s in see(camera, part, [], 5.0)] == ["p1"]
    cameras.blackout("cam", -math.inf)
    assert camera.dark(0.0) is False


@pytest.mark.parametrize(
    "kwargs",
    [
        {"h_fov_rad": 0.0},
        {"h_fov_rad": -0.1},
        {"v_fov_rad": math.pi},
        {"h_fov_rad": math.pi + 1},
        {"range_m": 0.0},
        {"range_m": -1.0},
        {"range_m": 1e308},
    ],
    ids=[
        "zero-fov",
        "negative-fov",
        "fov-180",
        "fov-over-180",
        "zero-range",
        "negative-range",
        "huge-range",
    ],
)
def test_bad_view_refused(kwargs: dict[str, float]) -> None:
    with pytest.raises(CameraError):
        _camera(**kwargs)


def test_registry_limit_and_unknown() -> None:
    told: list[list[str]] = []
    cameras = Cameras(lambda every: told.append([c.name for c in every]), limit=2)
    cameras.put(Camera("a", pin.SE3.Identity()))
    cameras.put(Camera("b", pin.SE3.Identity()))
    cameras.put(Camera("a", pin.SE3.Identity()))  # replacing is not adding
    with pytest.raises(TooManyCameras, match="2 cameras"):
        cameras.put(Camera("c", pin.SE3.Identity()))
    with pytest.raises(UnknownCamera, match=r"no camera named 'z' \(cameras: a, b\)"):
        cameras.get("z")
    cameras.remove("a")
    assert told == [["a"], ["a", "b"], ["a", "b"], ["b"]]


def test_the_docs_limits_are_the_code() -> None:
    from support import ROOT

    from c2rviz.protocol.verbs.parts import MAX_CAMERA_RATE_HZ, MAX_SIGMA_M
    from c2rviz.world import cameras

    table = (ROOT / "docs" / "cameras.md").read_text().split("## Limits")[1]
    rows = {
        line.split("|")[1].strip(): line.split("|")[2].strip()
        for line in table.splitlines()[3:]
        if line.startswith("|")
    }
    assert rows["Cameras in a world"] == str(cameras.MAX_CAMERAS)
    assert rows["A camera's range"] == f"above 0, at most {cameras.MAX_RANGE_M:g} m"
    assert rows["`watch` lines a second per camera"] == (
        f"0..{cameras.MAX_RATE_HZ:g} (default {cameras.DEFAULT_RATE_HZ:g})"
    )
    assert MAX_CAMERA_RATE_HZ == cameras.MAX_RATE_HZ
    assert rows["Noise"].startswith(f"0..{MAX_SIGMA_M:g} m")
    limits = (ROOT / "docs" / "limits.md").read_text()
    assert f"| {cameras.MAX_CAMERAS}; above 0 ..{cameras.MAX_RANGE_M:g} m;" in limits


def _inside(shape: str, size: tuple[float, ...], points: np.ndarray) -> np.ndarray:
    if shape == "box":
        return np.all(np.abs(points) <= np.array(size) / 2.0, axis=1)
    if shape == "sphere":
        return np.linalg.norm(points, axis=1) <= size[0]
    radius, length = size
    return (np.linalg.norm(points[:, :2], axis=1) <= radius) & (np.abs(points[:, 2]) <= length / 2)


@pytest.mark.parametrize("shape", ["box", "sphere", "cylinder"])
def test_the_segment_test_agrees_with_dense_sampling(shape: str) -> None:
    from c2rviz.world.cameras import segments_hit

    rng = np.random.default_rng(11)
    size = {"box": (0.2, 0.3, 0.25), "sphere": (0.15,), "cylinder": (0.12, 0.3)}[shape]
    steps = np.linspace(0.0, 1.0, 4001)[:, None]
    for _ in range(40):
        a = rng.uniform(-0.6, 0.6, 3)
        b = rng.uniform(-0.6, 0.6, (25, 3))
        exact = segments_hit(shape, size, a, b)
        for k, end in enumerate(b):
            points = a + steps * (end - a)
            smaller = _inside(shape, tuple(v * 0.95 for v in size), points).any()
            larger = _inside(shape, tuple(v * 1.05 for v in size), points).any()
            assert (not smaller or exact[k]) and (not exact[k] or larger), (a, end)
