"""Collisions: real Pinocchio models of the bundled robots, real coal checks."""

from __future__ import annotations

import math
from itertools import combinations
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from support import ROOT, load_robot

from c2rviz.collision.geometry import SrdfError, parse_srdf, read_srdf
from c2rviz.collision.model import CollisionModel, NoFreeConfiguration, segment
from c2rviz.collision.workcell import (
    DEFAULT_RGBA,
    BadColour,
    BadMesh,
    BadObjectName,
    BadPlacement,
    BadShape,
    BadSize,
    TooManyObjects,
    UnknownObject,
    WorkcellError,
)
from c2rviz.robot.model import Robot
from c2rviz.robot.sources import load_source

DATA = ROOT / "tests" / "data"
SLOT = DATA / "collision" / "slot.urdf"
SRDF = DATA / "collision" / "motoman.srdf"
TREE = DATA / "tree_robot" / "tree.urdf"
HAND_STL = DATA / "tree_robot" / "meshes" / "hand.stl"
ROBOTS = ["motoman_sia20d", "fanuc_lrmate200id", "kuka_lwr"]
d = math.radians


def at(x: float, y: float, z: float) -> pin.SE3:
    """A placement at (x, y, z) [m] in the base frame, unrotated."""
    return pin.SE3(np.eye(3), np.array([x, y, z]))


def home(robot: Robot) -> list[float]:
    return [min(max(0.0, joint.lower), joint.upper) for joint in robot.joints]


@pytest.fixture
def motoman() -> CollisionModel:
    return CollisionModel(load_robot("motoman_sia20d"))


# --- the robot against itself -------------------------------------------------


@pytest.mark.parametrize("name", ROBOTS)
def test_home_is_free(name: str) -> None:
    robot = load_robot(name)
    model = CollisionModel(robot)
    assert model.colliding(home(robot)) == []
    assert model.is_free(home(robot))
    assert model.warnings == ()


@pytest.mark.parametrize(
    ("name", "q_deg", "pair"),
    [
        # the arm folded down and back onto its own base
        ("motoman_sia20d", [0, -106, 0, 122, 0, 0, 0], ("base_link", "link_r")),
        # the wrist bent back onto the forearm
        ("fanuc_lrmate200id", [0, 0, 0, 0, 124, 0], ("link_4", "link_6")),
        # the flange bent onto the segment below the wrist
        ("kuka_lwr", [0, 0, 0, 0, 0, 90, 0], ("lwr_5_link", "lwr_7_link")),
    ],
    ids=["motoman", "fanuc", "kuka"],
)
def test_a_folded_arm_collides_with_itself(
    name: str, q_deg: list[float], pair: tuple[str, str]
) -> None:
    robot = load_robot(name)
    model = CollisionModel(robot)
    q = [d(v) for v in q_deg]
    pairs = model.colliding(q)
    assert pair in pairs
    assert pairs == sorted(pairs)
    assert not model.is_free(q)
    assert pair[0] in model.links_in(pairs) and pair[1] in model.links_in(pairs)
    # a straight joint move from home into the fold is stopped before its end
    hit = model.first_collision_on_segment(home(robot), q)
    assert hit is not None and 0.0 < hit[0] <= 1.0


# The pairs each bundled URDF leaves unchecked besides adjacent ones. A change to
# the URDFs' collision geometry that alters them shows up here.
EXPECTED_SKIPPED = {
    "motoman_sia20d": {
        "at_home": {("base_link", "link_l"), ("link_b", "link_u"), ("link_l", "link_u")},
        "always": set(),
        "rigid": set(),
    },
    "fanuc_lrmate200id": {
        "at_home": {("base_link", "link_2"), ("link_2", "link_4")},
        "always": set(),
        "rigid": set(),
    },
    "kuka_lwr": {"at_home": set(), "always": set(), "rigid": set()},
}


@pytest.mark.parametrize("name", ROBOTS)
def test_the_pairs_left_unchecked_are_these(name: str) -> None:
    robot = load_robot(name)
    pairs = CollisionModel(robot, seed=0).self_pairs
    assert pairs.samples == 2000
    assert set(pairs.at_home) == EXPECTED_SKIPPED[name]["at_home"]
    assert set(pairs.always) == EXPECTED_SKIPPED[name]["always"]
    assert set(pairs.rigid) == EXPECTED_SKIPPED[name]["rigid"]
    assert pairs.srdf == frozenset()
    # every pair of links is in exactly one set
    links = sorted({link for pair in pairs.checked | pairs.adjacent for link in pair})
    sets = [pairs.checked, pairs.adjacent, pairs.srdf, pairs.rigid, pairs.at_home, pairs.always]
    assert sum(len(s) for s in sets) == len(list(combinations(links, 2)))
    assert set().union(*sets) == set(combinations(links, 2))
    # a serial arm: each link is adjacent to the next one only; a gripper's hand (the
    # fanuc's) to the flange and to each finger besides
    on_gripper = {pair for pair in pairs.adjacent if "gripper_hand" in pair}
    assert len(on_gripper) == (3 if robot.gripper is not None else 0)
    assert len(pairs.adjacent) - len(on_gripper) == robot.n


def test_a_pair_touching_in_nearly_every_sample_is_not_checked() -> None:
    robot = Robot.from_urdf(SLOT)  # a rod in a slot 3 times its thickness
    model = CollisionModel(robot)
    assert model.self_pairs.always == {("link1", "rod")}
    assert model.self_pairs.at_home == frozenset()
    assert model.self_pairs.checked == {("base_link", "hub"), ("base_link", "rod")}
    assert model.colliding([0.0, 1.0]) == []
    # without sampling the same pair is checked, and does touch there
    unsampled = CollisionModel(robot, samples=0)
    assert unsampled.self_pairs.always == frozenset()
    assert unsampled.colliding([0.0, 1.0]) == [("link1", "rod")]
    assert unsampled.colliding([0.0, 0.0]) == []


@pytest.mark.parametrize("name", ["slot", "fanuc_lrmate200id"])
def test_sampling_stops_early_with_the_answer_of_every_draw(name: str) -> None:
    """Dropping pairs that missed too often changes nothing: count every draw here."""
    robot = Robot.from_urdf(SLOT) if name == "slot" else load_robot(name)
    every = CollisionModel(robot, samples=0)  # checks every pair not touching at home
    rng = np.random.default_rng(4)
    counts: dict[tuple[str, str], int] = {}
    for _ in range(400):
        for pair in every.colliding(robot.random(rng)):
            counts[pair] = counts.get(pair, 0) + 1
    expected = {pair for pair, n in counts.items() if n >= 380}
    assert CollisionModel(robot, samples=400, seed=4).self_pairs.always == expected
    assert (expected == {("link1", "rod")}) == (name == "slot")


def test_the_chosen_pairs_follow_the_seed() -> None:
    robot = Robot.from_urdf(SLOT)
    first = CollisionModel(robot, samples=300, seed=7).self_pairs
    assert CollisionModel(robot, samples=300, seed=7).self_pairs == first


@pytest.mark.parametrize("name", ROBOTS)
def test_colliding_agrees_with_coal_distances(name: str) -> None:
    """Every checked pair is in collision exactly when coal's distance is negative."""
    robot = load_robot(name)
    model = CollisionModel(robot)
    model.set_object("crate", "box", (0.3, 0.3, 0.3), at(0.5, 0.2, 0.6))
    model.set_object("ball", "sphere", (0.15,), at(-0.4, 0.0, 0.9))
    checks = model.check_geometry()
    geometry, names = checks.geometry, checks.names
    reference = pin.GeometryData(geometry)
    rng = np.random.default_rng(3)
    compared = 0
    for _ in range(300):
        q = robot.random(rng)
        pin.updateGeometryPlacements(
            robot.model, robot.model.createData(), geometry, reference, robot.configuration(q)
        )
        distance = [
            pin.computeDistance(geometry, reference, k).min_distance for k in range(len(names))
        ]
        if min(abs(x) for x in distance) < 1e-6:
            continue  # touching to within a micrometre: either answer is right
        expected = sorted({names[k] for k, x in enumerate(distance) if x < 0})
        assert model.colliding(q) == expected, np.degrees(q)
        assert model.is_free(q) == (not expected)
        compared += 1
    assert compared > 250


def test_the_answer_does_not_depend_on_what_was_checked_before() -> None:
    robot = load_robot("kuka_lwr")
    model = CollisionModel(robot)
    rng = np.random.default_rng(5)
    qs = [robot.random(rng) for _ in range(2000)]
    forward = [model.colliding(q) for q in qs]
    backward = [model.colliding(q) for q in reversed(qs)][::-1]
    assert forward == backward
    assert any(forward) and not all(forward)


# --- where the geometry comes from -------------------------------------------


def test_links_without_collision_elements_use_their_visuals() -> None:
    robot = Robot.from_urdf(TREE, "base_link", "tool0")  # visuals only; mimic; a mesh
    model = CollisionModel(robot)
    assert model.warnings == ()
    links = {link for pair in model.self_pairs.checked | model.self_pairs.adjacent for link in pair}
    # every link with a visual, the mimic finger and the off-chain camera included
    assert links == {
        "base_link",
        "carriage",
        "upper_arm",
        "forearm",
        "hand",
        "finger_left",
        "finger_right",
        "mast",
        "camera",
    }
    # the camera and the base never move relative to each other (the camera is off the chain)
    assert model.self_pairs.rigid == {("base_link", "camera")}
    assert ("camera", "mast") in model.self_pairs.adjacent


def test_a_missing_mesh_is_a_warning_and_a_package_path_finds_it() -> None:
    tiny = DATA / "tiny_ws" / "src" / "tiny_description" / "urdf" / "tiny.urdf"
    robot = Robot.from_source(load_source(tiny, environ={}))
    model = CollisionModel(robot)
    assert len(model.warnings) == 1
    assert "package://tiny_gripper/meshes/finger.stl" in model.warnings[0]
    assert "link2" in model.warnings[0]
    links = {link for pair in model.self_pairs.adjacent for link in pair}
    assert links == {"base_link", "link1"}  # base_link's visual mesh; link1's cylinder
    gripper = DATA / "tiny_ws" / "src" / "gripper-checkout"
    found = Robot.from_source(load_source(tiny, [f"tiny_gripper={gripper}"], environ={}))
    model = CollisionModel(found)
    assert model.warnings == ()
    assert ("link1", "link2") in model.self_pairs.adjacent


# --- the workcell ---------------------------------------------------------------


def test_a_box_in_the_way_collides_after_a_move_into_it(motoman: CollisionModel) -> None:
    robot = motoman.robot
    motoman.set_object("crate", "box", (0.2, 0.2, 0.2), at(0.8, 0.0, 0.41))
    assert motoman.colliding(home(robot)) == []
    down = [0, d(90), 0, 0, 0, 0, 0]  # the arm level, pointing along +x through the crate
    pairs = motoman.colliding(down)
    assert pairs == [("link_r", "crate"), ("link_u", "crate")]
    assert motoman.links_in(pairs) == ["link_r", "link_u"]
    path = segment(robot, home(robot), down)
    hit = motoman.first_collision(path)
    assert hit is not None
    index, pair = hit
    assert 0 < index < len(path)
    assert pair[1] == "crate"
    assert motoman.is_free(path[index - 1])
    assert motoman.first_collision(path[:index]) is None
    motoman.remove_object("crate")
    assert motoman.colliding(down) == []
    assert motoman.first_collision(path) is None


def test_a_path_with_free_ends_that_crosses_a_box_is_caught(motoman: CollisionModel) -> None:
    motoman.set_object("crate", "box", (0.2, 0.2, 0.2), at(0.8, 0.0, 0.41))
    start = [d(-90), d(90), 0, 0, 0, 0, 0]  # level, pointing along -y
    end = [d(90), d(90), 0, 0, 0, 0, 0]  # level, pointing along +y
    assert motoman.colliding(start) == [] and motoman.colliding(end) == []
    hit = motoman.first_collision_on_segment(start, end)
    assert hit is not None
    fraction, pair = hit
    assert 0.3 < fraction < 0.5  # turning through +x, before it points at the crate
    assert pair[1] == "crate"
    assert motoman.first_collision([start, end]) is None  # the ends alone miss it


def test_segment_steps_at_most_one_degree_and_keeps_the_ends() -> None:
    robot = load_robot("motoman_sia20d")
    q0 = [0.0] * 7
    q1 = [d(90), d(-45), 0, 0, 0, 0, d(10)]
    path = segment(robot, q0, q1)
    assert path[0] == tuple(q0) and np.allclose(path[-1], q1)
    assert len(path) == 91
    steps = np.abs(np.diff(np.array(path), axis=0))
    assert steps.max() <= d(1) + 1e-12
    assert segment(robot, q0, q0) == [tuple(q0), tuple(q0)]
    tree = Robot.from_urdf(TREE, "base_link", "tool0")  # lift is prismatic: 5 mm steps
    lifted = segment(tree, [0, 0, 0, 0], [0.5, d(2), 0, 0])
    assert len(lifted) == 101


def test_random_free_draws_only_free_configurations(motoman: CollisionModel) -> None:
    motoman.set_object("crate", "box", (0.4, 0.4, 0.4), at(0.6, 0.0, 0.6))
    rng = np.random.default_rng(11)
    robot = motoman.robot
    for _ in range(200):
        q = motoman.random_free(rng)
        assert motoman.colliding(q) == []
        assert all(lo <= v <= hi for v, lo, hi in zip(q, robot.lower, robot.upper))


def test_random_free_gives_up_with_a_clear_error(motoman: CollisionModel) -> None:
    motoman.set_object("cage", "box", (5, 5, 5), at(0, 0, 0))  # the robot is inside it
    with pytest.raises(NoFreeConfiguration, match="in 50 random draws"):
        motoman.random_free(np.random.default_rng(0), tries=50)


def test_objects_never_collide_with_links_that_do_not_move(motoman: CollisionModel) -> None:
    # a table through the base plate: the base cannot move off it, so it does not count
    motoman.set_object("table", "box", (1.6, 1.6, 0.02), at(0, 0, -0.005))
    assert motoman.colliding(home(motoman.robot)) == []
    reaching_down = [0, d(100), 0, d(-60), 0, 0, 0]
    assert motoman.colliding(reaching_down) == [("link_r", "table"), ("link_u", "table")]


def test_a_mesh_object_is_checked_as_its_triangles(motoman: CollisionModel) -> None:
    wedge = motoman.set_object("wedge", "mesh", (4,), at(0.7, 0, 0.35), mesh_path=HAND_STL)
    assert wedge.size == (4.0, 4.0, 4.0) and wedge.mesh_path == HAND_STL.resolve()
    assert motoman.colliding(home(motoman.robot)) == []
    assert ("link_u", "wedge") in motoman.colliding([0, d(90), 0, 0, 0, 0, 0])


def test_objects_are_listed_for_drawing(motoman: CollisionModel) -> None:
    place = at(0.5, 0.1, 0.2)
    motoman.set_object("b", "box", [0.1, 0.2, 0.3], place)
    motoman.set_object("a", "cylinder", (0.05, 0.4), at(0, 0.5, 0), rgba=(1, 0, 0))
    motoman.set_object("c", "sphere", (0.1,), at(0, -0.5, 0), rgba=(0, 1, 0, 0.3))
    place.translation = np.zeros(3)  # the caller's placement is copied, not kept
    assert motoman.objects() == ["b", "a", "c"]
    b, a, c = motoman.object_list()
    assert (b.shape, b.size, b.rgba) == ("box", (0.1, 0.2, 0.3), DEFAULT_RGBA)
    assert np.allclose(b.placement.translation, [0.5, 0.1, 0.2])
    assert a.rgba == (1.0, 0.0, 0.0, 1.0) and c.rgba == (0.0, 1.0, 0.0, 0.3)
    assert DEFAULT_RGBA[3] < 1.0  # translucent by default
    motoman.set_object("b", "sphere", (0.2,), at(0, 0, 3))  # replaced in place
    assert motoman.objects() == ["b", "a", "c"]
    assert motoman.workcell.get("b").shape == "sphere"
    motoman.remove_object("a")
    assert motoman.objects() == ["b", "c"]
    motoman.remove_all()
    assert motoman.objects() == [] and motoman.object_list() == []


BAD_OBJECTS = [
    (("crate", "box", (-0.1, 0.2, 0.2)), BadSize, "x,y,z, each > 0 and finite"),
    (("crate", "box", (0.0, 0.2, 0.2)), BadSize, "value 0 is not > 0"),
    (("crate", "box", (float("nan"), 0.2, 0.2)), BadSize, "value nan"),
    (("crate", "sphere", (float("inf"),)), BadSize, "a sphere takes radius"),
    (("crate", "box", (0.1, 0.2)), BadSize, "needs 3 values, got 2"),
    (("crate", "cylinder", (0.1,)), BadSize, "radius,length"),
    (("crate", "box", ("a", 1, 1)), BadSize, "not a list of numbers"),
    (("crate", "cone", (0.1,)), BadShape, "choose from: box, cylinder, mesh, sphere"),
    (("my crate", "box", (1, 1, 1)), BadObjectName, "no spaces or '/'"),
    (("a/b", "box", (1, 1, 1)), BadObjectName, "no spaces or '/'"),
    (("", "box", (1, 1, 1)), BadObjectName, "letters, digits"),
    (("crète", "box", (1, 1, 1)), BadObjectName, "letters, digits"),
    (("all", "box", (1, 1, 1)), BadObjectName, "reserved"),
    (("ALL", "box", (1, 1, 1)), BadObjectName, "reserved"),
    (("link_t", "box", (1, 1, 1)), BadObjectName, "is a link of the robot"),
    (("x" * 65, "box", (1, 1, 1)), BadObjectName, "longer than 64"),
]


@pytest.mark.parametrize(
    ("args", "error", "message"), BAD_OBJECTS, ids=[str(i) for i in range(len(BAD_OBJECTS))]
)
def test_bad_objects_are_refused(
    motoman: CollisionModel, args: tuple, error: type[WorkcellError], message: str
) -> None:
    with pytest.raises(error, match=message.replace("(", r"\(").replace(".", r"\.")):
        motoman.set_object(*args, placement=at(0, 0, 0))
    assert motoman.objects() == []


def test_bad_colour_placement_and_mesh_are_refused(motoman: CollisionModel, tmp_path: Path) -> None:
    with pytest.raises(BadColour, match="r,g,b or r,g,b,a with each value in 0..1"):
        motoman.set_object("a", "box", (1, 1, 1), at(0, 0, 0), rgba=(1, 2, 0))
    nowhere = pin.SE3(np.eye(3), np.array([0.0, math.nan, 0.0]))
    with pytest.raises(BadPlacement, match="non-finite"):
        motoman.set_object("a", "box", (1, 1, 1), nowhere)
    with pytest.raises(BadMesh, match="no such file"):
        motoman.set_object("a", "mesh", (), at(0, 0, 0), mesh_path=tmp_path / "none.stl")
    with pytest.raises(BadMesh, match="no file was given"):
        motoman.set_object("a", "mesh", (), at(0, 0, 0))
    with pytest.raises(BadMesh, match="only a mesh takes a file"):
        motoman.set_object("a", "box", (1, 1, 1), at(0, 0, 0), mesh_path=HAND_STL)
    junk = tmp_path / "junk.stl"
    junk.write_text("not a mesh")
    with pytest.raises(BadMesh, match="cannot be read"):
        motoman.set_object("a", "mesh", (), at(0, 0, 0), mesh_path=junk)
    assert motoman.objects() == []


def test_the_workcell_holds_at_most_max_objects() -> None:
    model = CollisionModel(load_robot("motoman_sia20d"), max_objects=3)
    for name in "abc":
        model.set_object(name, "sphere", (0.1,), at(2, 0, 0))
    with pytest.raises(TooManyObjects, match="already holds 3 objects"):
        model.set_object("d", "sphere", (0.1,), at(2, 0, 0))
    model.set_object("a", "sphere", (0.2,), at(2, 0, 0))  # replacing is not adding
    model.remove_object("b")
    model.set_object("d", "sphere", (0.1,), at(2, 0, 0))
    assert model.objects() == ["a", "c", "d"]
    with pytest.raises(UnknownObject, match=r"no object named 'b' \(objects: a, c, d\)"):
        model.remove_object("b")


# --- SRDF ---------------------------------------------------------------------------


def test_srdf_disabled_pairs_are_not_checked() -> None:
    disabled = read_srdf(SRDF)
    assert disabled == [("base_link", "link_r"), ("base_link", "link_b"), ("link_l", "link_s")]
    robot = load_robot("motoman_sia20d")
    model = CollisionModel(robot, disabled=disabled)
    assert model.self_pairs.srdf == {("base_link", "link_r"), ("base_link", "link_b")}
    assert ("link_l", "link_s") in model.self_pairs.adjacent  # adjacent comes first
    folded = [0, d(-106), 0, d(122), 0, 0, 0]
    assert CollisionModel(robot).colliding(folded) == [
        ("base_link", "link_b"),
        ("base_link", "link_r"),
        ("base_link", "link_u"),
    ]
    assert model.colliding(folded) == [("base_link", "link_u")]


def test_srdf_problems() -> None:
    with pytest.raises(SrdfError, match="not valid XML"):
        parse_srdf("<robot>")
    with pytest.raises(SrdfError, match="lacks link1 or link2"):
        parse_srdf('<robot><disable_collisions link1="a"/></robot>')
    with pytest.raises(SrdfError, match="cannot read SRDF"):
        read_srdf(ROOT / "no-such.srdf")
    model = CollisionModel(load_robot("kuka_lwr"), disabled=[("lwr_1_link", "gripper")])
    assert model.warnings == ("disabled pairs name links lwr lacks: gripper",)
