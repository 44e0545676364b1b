"""The four levels of body-body collision (claim C3) on constructed
configurations, the oracles' body-level answers classified, and the
hierarchy benchmark's configurations (refsim.studies.levels).

Known answers come from exactly representable geometry: cube.ac is
[-0.5, 0.5]^3, so a translation by (1, 0, 0) makes two cubes share the face
x = 0.5 with no rounding anywhere, and (1, 1, 1) makes them share one corner.

Measured (seed 0, 10 random poses per model pair; reproduce with
``refsim study collision-levels --quick``): zero false negatives
at every level; FCL's face pairs and boolean answers equal refsim's on every
query; trimesh's CollisionManager differs only by "known-divergence",
reason "containment" (a small convex body inside a convex one: a solid for
trimesh, two surfaces apart for refsim) and "touching" (cubes sharing a face
or a corner: GJK on two fcl.Convex says apart). The classifier itself is
tested on constructed cases in tests/collision/test_body_disagreement.py.
"""

from __future__ import annotations

import numpy as np
import pytest
from refsim.oracles.fcl_adapter import FCLOracle
from refsim.oracles.trimesh_collision import TrimeshCollisionOracle, float32_pose

import refsim
from refsim.collision.bodies import LEVELS, bodies_collide, intersecting_pairs
from refsim.studies.levels import (
    CONFIGURATIONS,
    SPEED_CONFIGURATIONS,
    Configuration,
    bundled_mesh,
    classify_body_disagreement,
    measure_body_oracles,
    measure_hierarchy_speed,
    measure_levels,
)

IDENTITY = (np.eye(3), np.zeros(3))


def at(x, y=0.0, z=0.0):
    return np.eye(3), np.array([x, y, z], dtype=np.float64)


def answers(mesh_a, pose_a, mesh_b, pose_b, method="bvh", kernel=None):
    return {level: bool(bodies_collide(mesh_a, pose_a, mesh_b, pose_b, level=level,
                                       method=method, kernel=kernel)) for level in LEVELS}


def level_answers(sphere, aabb, triangle_aabb, exact):
    return dict(zip(LEVELS, (sphere, aabb, triangle_aabb, exact), strict=True))


# Every constructed configuration's answers at (sphere, aabb, triangle-aabb,
# exact), worked out from the geometry in CONFIGURATIONS' descriptions.
EXPECTED = {
    "far": level_answers(False, False, False, False),
    "spheres-2.1": level_answers(False, True, True, False),       # spheres 2.1 > 2 apart
    "tori-2.72": level_answers(False, True, True, False),         # 2.72 > 2 * 1.35
    "l-beams-nested": level_answers(True, True, False, False),
    "cubes-face": level_answers(True, True, True, True),
    "cubes-corner": level_answers(True, True, True, True),
    "spheres-1.99": level_answers(True, True, True, True),
    "tori-2.66": level_answers(True, True, True, True),
    "spheres-1.0": level_answers(True, True, True, True),
    "tori-1.0": level_answers(True, True, True, True),
    "icosahedron-in-sphere": level_answers(True, True, False, False),
    "cube-in-torus-hole": level_answers(True, True, True, False),
    "cube-in-cube": level_answers(True, True, False, False),
}


@pytest.fixture(scope="module")
def levels():
    # One repeat per timing and 10 random poses per model pair: the answers
    # and counts are what is tested here, not the times.
    return measure_levels(repeats=1, random_per_pair=10, seed=0)


@pytest.fixture
def fcl(oracle):
    return oracle(FCLOracle)


@pytest.fixture
def trimesh_oracle(oracle):
    return oracle(TrimeshCollisionOracle)


def engine_collides(engine, mesh_a, pose_a, mesh_b, pose_b) -> bool:
    """An engine's ``bodies_collide`` on two refsim meshes."""
    return engine.bodies_collide(mesh_a.vertices, mesh_a.faces, pose_a, mesh_b.vertices,
                                 mesh_b.faces, pose_b)


class Answering:
    """A ``collide`` engine that gives one answer to every query, with the
    declarations given (refsim.engines.declarations)."""

    def __init__(self, name, answer, **declared):
        self.name, self.answer = name, answer
        self.__dict__.update(declared)

    def bodies_collide(self, *arrays):
        return self.answer


# -- known answers ---------------------------------------------------------------------

def test_expected_table_covers_every_configuration():
    assert set(EXPECTED) == {c.name for c in CONFIGURATIONS}


@pytest.mark.parametrize("method", ["bvh", "seed"])
@pytest.mark.parametrize("config", CONFIGURATIONS, ids=lambda c: c.name)
def test_constructed_configurations(config, method):
    (mesh_a, mesh_b), (pose_a, pose_b) = config.meshes(), config.poses()
    got = answers(mesh_a, pose_a, mesh_b, pose_b, method=method)
    assert got == EXPECTED[config.name]
    assert got["exact"] == config.intended


def test_an_unknown_rotation_is_named():
    # it was unpacked as (axis, angle): "too many values to unpack"
    config = Configuration("x", "separated-far", "", "cube", "cube", rotation_b="fixd")
    with pytest.raises(ValueError, match="rotation_b 'fixd'"):
        config.poses()


def test_cubes_sharing_a_face_touch():
    cube = bundled_mesh("cube")
    assert answers(cube, IDENTITY, cube, at(1.0)) == level_answers(True, True, True, True)
    # The touching pairs are the faces on x = 0.5 of A and x = -0.5 of B (two
    # triangles each, coplanar) and the side faces meeting along that square.
    pairs = intersecting_pairs(cube, IDENTITY, cube, at(1.0))
    world_a = cube.vertices[cube.faces[pairs[:, 0]]]
    world_b = cube.vertices[cube.faces[pairs[:, 1]]] + [1.0, 0.0, 0.0]
    # every reported pair has a point on the shared plane x = 0.5
    assert (world_a[:, :, 0] == 0.5).any(axis=1).all()
    assert (world_b[:, :, 0] == 0.5).any(axis=1).all()
    np.testing.assert_array_equal(pairs, intersecting_pairs(cube, IDENTITY, cube, at(1.0),
                                                            method="seed"))


def test_cubes_one_float_apart_do_not_touch():
    cube = bundled_mesh("cube")
    # The next double after 1: B's face is at -0.5 + (1 + 2**-52) = 0.5 + 2**-52
    # (exact), so even the boxes are apart; only the spheres still overlap.
    gap = np.nextafter(1.0, 2.0)
    assert answers(cube, IDENTITY, cube, at(gap)) == level_answers(True, False, False, False)


def test_cubes_sharing_a_corner_touch():
    cube = bundled_mesh("cube")
    assert answers(cube, IDENTITY, cube, at(1.0, 1.0, 1.0)) == level_answers(True, True, True,
                                                                             True)
    # All pairs meet at the one corner (0.5, 0.5, 0.5).
    pairs = intersecting_pairs(cube, IDENTITY, cube, at(1.0, 1.0, 1.0))
    assert len(pairs) > 0
    corner = np.array([0.5, 0.5, 0.5])
    for i, j in pairs:
        assert (cube.vertices[cube.faces[i]] == corner).all(axis=1).any()
        assert (cube.vertices[cube.faces[j]] + 1.0 == corner).all(axis=1).any()


def test_containment_is_not_a_collision_for_refsim():
    # A cube of side 0.5 at the centre of the unit cube: the surfaces are 0.25
    # apart everywhere. The coarse levels say "collide" (their volumes
    # overlap); the exact level, which intersects surfaces, says no.
    cube, small = bundled_mesh("cube"), bundled_mesh("cube", 0.5)
    assert answers(cube, IDENTITY, small, IDENTITY) == level_answers(True, True, False, False)


@pytest.mark.oracle
def test_containment_collides_for_trimesh(trimesh_oracle):
    # Documented difference: trimesh makes both convex cubes fcl.Convex solids,
    # so the small one inside the big one collides; refsim says False.
    cube, small = bundled_mesh("cube"), bundled_mesh("cube", 0.5)
    assert engine_collides(trimesh_oracle, cube, IDENTITY, small, IDENTITY) is True
    verdict = classify_body_disagreement(cube, IDENTITY, small, IDENTITY, False,
                                         trimesh_oracle)
    assert (verdict.kind, verdict.reason) == ("known-divergence", "containment")
    assert verdict.gap == 0.25                  # the small cube's faces to the big one's


@pytest.mark.oracle
def test_containment_in_a_non_convex_body_is_not_found_by_trimesh(trimesh_oracle):
    # The torus is a surface (BVHModel) for trimesh: a cube in its hole does
    # not collide there either.
    config = next(c for c in CONFIGURATIONS if c.name == "cube-in-torus-hole")
    (torus, cube), (pose_a, pose_b) = config.meshes(), config.poses()
    assert trimesh_oracle.is_solid(torus.vertices, torus.faces) is False
    assert engine_collides(trimesh_oracle, torus, pose_a, cube, pose_b) is False


# -- the classifier ----------------------------------------------------------------------

@pytest.mark.oracle
def test_float32_transform_is_classified(trimesh_oracle):
    # Two L-beams (non-convex: BVHModels for trimesh) a gap of 2**-30 apart
    # along z. float32(0.5 + 2**-30) == 0.5: trimesh sees them touching.
    beam = bundled_mesh("l-beam")
    pose_b = at(0.0, 0.0, 0.5 + 2.0 ** -30)
    assert bodies_collide(beam, IDENTITY, beam, pose_b) is False
    assert bodies_collide(beam, IDENTITY, beam, float32_pose(pose_b)) is True
    assert engine_collides(trimesh_oracle, beam, IDENTITY, beam, pose_b) is True
    verdict = classify_body_disagreement(beam, IDENTITY, beam, pose_b, False,
                                         trimesh_oracle)
    assert (verdict.kind, verdict.reason) == ("tolerance", "float32 transform")
    assert verdict.gap == 2.0 ** -30            # the beams' faces z = 0.5 and 0.5 + 2**-30


@pytest.mark.oracle
def test_touching_cubes_are_classified(trimesh_oracle):
    cube = bundled_mesh("cube")
    assert engine_collides(trimesh_oracle, cube, IDENTITY, cube, at(1.0)) is False
    verdict = classify_body_disagreement(cube, IDENTITY, cube, at(1.0), True,
                                         trimesh_oracle)
    assert (verdict.kind, verdict.reason, verdict.gap) == ("touching", "touching", 0.0)


def test_tolerance_and_bug_classes():
    # An engine that always says "apart", declaring GJK's distance tolerance
    # of 1e-6 m: on cubes overlapping by 2**-24 (z from 0.5 - 2**-24 to 0.5,
    # exact) it is within its tolerance; on cubes overlapping by 0.25 it is a
    # bug. The gap is minus the deepest exact pair's depth.
    apart = Answering("apart", False, distance_tolerance=1e-6)
    cube = bundled_mesh("cube")
    shallow = at(0.25, 0.125, 1.0 - 2.0 ** -24)
    verdict = classify_body_disagreement(cube, IDENTITY, cube, shallow, True, apart)
    assert (verdict.kind, verdict.reason) == ("tolerance", "gap within tolerance")
    assert verdict.gap == -(2.0 ** -24)
    deep = at(0.25, 0.125, 0.75)
    verdict = classify_body_disagreement(cube, IDENTITY, cube, deep, True, apart)
    assert (verdict.kind, verdict.reason, verdict.gap) == ("bug", "gap beyond tolerance", -0.25)
    # An engine that always says "collide" on bodies 0.5 apart: a bug.
    always = Answering("always", True, distance_tolerance=1e-6)
    verdict = classify_body_disagreement(cube, IDENTITY, cube, at(1.5), False, always)
    assert (verdict.kind, verdict.reason, verdict.gap) == ("bug", "gap beyond tolerance", 0.5)


def test_an_undeclared_tolerance_is_not_granted():
    # The study's former rule called any answer that a move of 1e-6 of the
    # larger radius along the line of centres flips "tolerance", whatever the
    # engine declared; the kit holds an engine that declares no tolerance to
    # float64's rounding bound. An overlap of 2**-24 m on unit cubes is 2**29
    # units of float64 roundoff: not rounding, so missed by an engine that
    # declares nothing it is a bug (the kit's rule, now both's).
    apart = Answering("apart", False)
    cube = bundled_mesh("cube")
    verdict = classify_body_disagreement(cube, IDENTITY, cube, at(0.25, 0.125, 1.0 - 2.0 ** -24),
                                         True, apart)
    assert (verdict.kind, verdict.reason) == ("bug", "gap beyond tolerance")
    assert verdict.gap == -(2.0 ** -24)
    assert verdict.bound < 2.0 ** -30           # 2**14 ulps of the coordinates (1.5): 1.4e-12


# -- the measurement ---------------------------------------------------------------------

def test_no_false_negatives(levels):
    assert levels.false_negatives == 0
    for s in levels.summary:
        assert s.false_negatives == 0, s.level
    for r in levels.random:
        assert all(count == 0 for count in r.false_negatives.values()), r
    assert levels.level("exact").false_positives == 0


def test_coarse_levels_have_false_positives(levels):
    # Each coarse level answers "collide" on some configuration where the
    # surfaces do not meet (so C3's trade is real), and finer box levels
    # never have more false positives than coarser box levels.
    fp = {s.level: s.false_positives for s in levels.summary}
    assert fp["sphere"] > 0 and fp["aabb"] > 0 and fp["triangle-aabb"] > 0
    assert fp["aabb"] >= fp["triangle-aabb"] >= fp["exact"] == 0


def test_measured_configurations(levels):
    for c in levels.configurations:
        assert c.answers == EXPECTED[c.name], c.name
        assert c.seed_answers_equal, c.name
        assert c.exact_pairs <= c.candidate_pairs
        assert (c.exact_pairs > 0) == c.answers["exact"]
        assert all(t > 0 for t in c.seconds.values())
    for r in levels.random:
        assert r.seed_mismatches == 0
        assert r.exact_pairs <= r.candidate_pairs


def test_levels_are_deterministic():
    a = measure_levels(CONFIGURATIONS[:2], repeats=1, random_per_pair=3, seed=5)
    b = measure_levels(CONFIGURATIONS[:2], repeats=1, random_per_pair=3, seed=5)
    assert a.random == b.random
    assert [c.answers for c in a.configurations] == [c.answers for c in b.configurations]


@pytest.mark.oracle
def test_oracle_agreement_has_no_bug(fcl, trimesh_oracle):
    result = measure_body_oracles((fcl, trimesh_oracle), fcl, random_per_pair=10, seed=0)
    for b in result.bodies:
        print(f"\n{b.oracle} {b.source}: n={b.n} agree={b.agree} {b.counts}")
    for p in result.pairs:
        print(f"\nfcl pairs {p.source}: {p.queries_equal}/{p.queries} equal {p.counts}")
    assert result.bugs == 0
    # FCL (two BVHModels: surfaces, like refsim) agrees on every query.
    for p in result.pairs:
        assert p.queries_equal == p.queries
    for source in ("constructed", "random"):
        assert result.body("fcl", source).agree == result.body("fcl", source).n
    # trimesh on the constructed configurations: exactly the documented cases.
    found = {(d.case, d.kind, d.reason)
             for d in result.body("trimesh", "constructed").disagreements}
    assert found == {("cubes-face", "touching", "touching"),
                     ("cubes-corner", "touching", "touching"),
                     ("icosahedron-in-sphere", "known-divergence", "containment"),
                     ("cube-in-cube", "known-divergence", "containment")}
    random = result.body("trimesh", "random")
    assert set((d.kind, d.reason) for d in random.disagreements) <= {
        ("known-divergence", "containment"), ("touching", "touching"),
        ("tolerance", "float32 transform"), ("tolerance", "gap within tolerance")}
    for d in random.disagreements:              # a tolerance is within trimesh's declared one
        assert d.kind != "tolerance" or abs(d.gap) <= 1e-6


# -- the benchmark configurations --------------------------------------------------------

@pytest.mark.oracle
def test_speed_configurations_are_what_they_say(fcl):
    speed = measure_hierarchy_speed(fcl, repeats=1, compile_cost=False)
    assert len(speed.cases) == len(SPEED_CONFIGURATIONS)
    for c in speed.cases:
        assert c.fcl_pairs == c.exact_pairs
        assert c.seed_seconds > 0 and c.bvh_seconds > 0 and c.fcl_seconds > 0
        if c.kind == "separated-boxes-overlap":
            assert c.exact_pairs == 0 and c.candidate_pairs > 0
        elif c.kind == "grazing":
            assert 1 <= c.exact_pairs <= 50        # "a handful" (measured: 18, 20)
        elif c.kind == "touching":                 # the descriptions' counts
            assert (c.model, c.candidate_pairs, c.exact_pairs) in {("cube", 84, 62),
                                                                   ("sphere-2k+cube", 12, 12)}
        else:
            assert c.exact_pairs >= 100            # "hundreds" (measured: 198, 264)


# -- any finite scale ------------------------------------------------------------------

#: Powers of two from near the smallest normal float to near the largest; at
#: each, two bodies are scaled with their poses' translations (exact in binary
#: floating point), so every answer must equal the one at scale 1.
SCALE_EXPONENTS = [-1000, -600, -300, -100, 100, 300, 600, 900, 1010]


@pytest.mark.parametrize("exponent", SCALE_EXPONENTS)
def test_every_level_answers_the_same_at_any_scale(exponent):
    cube, ico = refsim.load_model("cube.ac"), refsim.load_model("icosahedron.ac")
    tilt = refsim.types.rotation_about_axis([1.0, 2.0, 3.0], 0.4)
    cases = [(cube, cube, 0.9), (ico, cube, 1.2), (cube, ico, 3.0)]   # overlap, near, apart
    s = 2.0 ** exponent
    for a, b, gap in cases:
        pa = (np.eye(3), np.array([-0.5 * gap, 0.0, 0.0]))
        pb = (tilt, np.array([0.5 * gap, 0.1, 0.0]))
        big_a, big_b = refsim.Mesh(a.vertices * s, a.faces), refsim.Mesh(b.vertices * s, b.faces)
        big_pa, big_pb = (pa[0], pa[1] * s), (pb[0], pb[1] * s)
        assert big_a.is_convex == a.is_convex
        for level in ("sphere", "aabb", "triangle-aabb", "exact"):
            assert (refsim.bodies_collide(big_a, big_pa, big_b, big_pb, level=level)
                    == refsim.bodies_collide(a, pa, b, pb, level=level)), (level, gap)
        assert np.array_equal(refsim.intersecting_pairs(big_a, big_pa, big_b, big_pb),
                              refsim.intersecting_pairs(a, pa, b, pb))


def test_the_sphere_level_is_conservative_near_float64s_largest_values():
    # two cubes with corners at +-5e307 whose centres are 6e307 apart overlap
    cube = refsim.load_model("cube.ac")
    huge = refsim.Mesh(cube.vertices * 1e308, cube.faces)
    a, b = (np.eye(3), np.zeros(3)), (np.eye(3), np.array([6e307, 0.0, 0.0]))
    assert refsim.bodies_collide(huge, a, huge, b, level="exact")
    for level in ("sphere", "aabb", "triangle-aabb"):
        assert refsim.bodies_collide(huge, a, huge, b, level=level)
