"""How a disagreement is classified: by exact geometry where the answer is
exact, by its gap or excess in metres against the rounding bound and what
the engine declares (refsim.engines.declarations), by a documented law where
the engine follows one."""

from __future__ import annotations

import math

import numpy as np
import pytest

from refsim.collision.gaps import penetration_depth, triangle_distance
from refsim.conformance.cases_boxes import BoxCase, exact_box, rounding_bound
from refsim.conformance.cases_meshes import PoseCase, PoseCases, _exact_pairs
from refsim.conformance.checks_geometry import (
    box_excess,
    check_aabb_encloses,
    check_aabb_tight,
    check_collide_agreement,
    classify_box,
    classify_collide,
    classify_pairs,
    classify_triangles,
)
from refsim.engines import Declarations, declarations
from refsim.errors import OptionError
from tests.conformance.broken_engines import BoxIgnoresRotation, GjkLikeCollide, PaddedBox

IDENTITY = (np.eye(3), np.zeros(3))
TRIANGLE = np.array([[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]])
#: A quarter turn about z, exact in binary: (x, y, z) -> (-y, x, z).
QUARTER_TURN = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])


def _case(model_a, pose_a, model_b, pose_b, gap=None):
    return PoseCase(model_a, model_b, pose_a, pose_b, "deep", gap,
                    _exact_pairs(model_a, pose_a, model_b, pose_b))


def _box_case(vertices, pose, family="random"):
    vertices = np.asarray(vertices, dtype=np.float64)
    return BoxCase(vertices, pose, family, exact_box(vertices, pose),
                   rounding_bound(vertices, pose))


def test_triangle_classes():
    touching = np.array([[0.5, 0.5, 0.0], [0.5, 0.5, 1.0], [1.0, 0.0, 1.0]])   # a vertex on a
    coplanar = np.array([[3.0, 3.0, 0.0], [4.0, 3.0, 0.0], [3.0, 4.0, 0.0]])
    crossing = np.array([[0.5, 0.5, -1.0], [0.5, 0.5, 1.0], [1.0, 0.0, 1.0]])
    assert classify_triangles(TRIANGLE, touching)["class"] == "touching"
    assert classify_triangles(TRIANGLE, touching)["gap_metres"] == 0.0
    assert classify_triangles(TRIANGLE, coplanar)["class"] == "coplanar"
    verdict = classify_triangles(TRIANGLE, crossing)
    assert verdict["class"] == "bug"                  # well conditioned: no excuse
    # B spans y in [0, 0.5] over A (y >= 0): moved 0.5 along -y it only
    # touches A's edge y = 0; no shorter move frees it
    assert verdict["gap_metres"] == -0.5


def test_a_near_parallel_pair_is_classed_by_its_gap_not_its_margin():
    # B in a plane 1e-11 above A: a GJK-like engine calls it touching
    lifted = np.array([[0.2, 0.2, 1e-11], [1.0, 0.2, 1e-11], [0.2, 1.0, 1e-11]])
    default = classify_triangles(TRIANGLE, lifted)
    assert default["class"] == "bug"                  # 1e-11 m: beyond 2^14 u * 2 m
    assert default["gap_metres"] == pytest.approx(1e-11, rel=1e-6)
    assert default["rounding_bound_metres"] == pytest.approx(2.0 ** 14 * 2.0 ** -53 * 2.0)
    declared = classify_triangles(TRIANGLE, lifted, distance_tolerance=1e-6)
    assert declared["class"] == "tolerance"
    assert declared["distance_tolerance_metres"] == 1e-6
    rounding = np.array([[0.2, 0.2, 1e-16], [1.0, 0.2, 1e-16], [0.2, 1.0, 1e-16]])
    assert classify_triangles(TRIANGLE, rounding)["class"] == "tolerance"


def test_gaps_against_closed_forms():
    # a unit right triangle, and one 0.25 above its plane over it
    above = TRIANGLE + np.array([0.0, 0.0, 0.25])
    assert triangle_distance(TRIANGLE, above) == 0.25
    # B's corner (3, 4, 0) to A's edge x + y = 2 (its foot (0.5, 1.5) on the edge)
    beside = TRIANGLE + np.array([3.0, 4.0, 0.0])
    assert triangle_distance(TRIANGLE, beside) == pytest.approx(5.0 / math.sqrt(2.0), rel=1e-15)
    # B pierces A's interior 0.1 deep below A's plane and 0.3 above: out by 0.1
    spike = np.array([[0.5, 0.5, -0.1], [0.5, 0.5, 0.3], [0.7, 0.5, 0.3]])
    assert penetration_depth(TRIANGLE, spike) == pytest.approx(0.1, rel=1e-12)


def test_a_body_inside_another_is_a_known_divergence_only_for_a_declared_solid():
    # the tetrahedron inside the sphere-2k: no surfaces meet (truth: apart),
    # a solid engine (trimesh's GJK on convex meshes) says they collide
    case = _case("sphere-2k.ac", IDENTITY, "tetrahedron.ac", (np.eye(3), np.array([0.1, 0.05, 0])))
    assert len(case.truth) == 0
    assert classify_collide(case, True, solid=True)["class"] == "known-divergence"
    # an engine that tests surfaces, as the contract asks, has no excuse
    verdict = classify_collide(case, True)
    assert verdict["class"] == "bug" and verdict["contained"] and not verdict["solid_declared"]


def test_solid_must_be_a_bool():
    from refsim.engines import declarations
    from refsim.errors import OptionError

    class Engine:
        name = "e"
        solid = "yes"

    with pytest.raises(OptionError, match="solid must be True or False"):
        declarations(Engine())


def test_a_grazing_gap_is_tolerance_only_within_the_declared_distance():
    near = _case("cube.ac", IDENTITY, "cube.ac", (np.eye(3), np.array([1.0 + 1e-9, 0.0, 0.0])))
    assert len(near.truth) == 0
    assert classify_collide(near, True, 1e-6)["class"] == "tolerance"
    verdict = classify_collide(near, True)                  # nothing declared
    assert verdict["class"] == "bug"
    assert verdict["gap_metres"] == pytest.approx(1e-9, rel=1e-6)
    assert verdict["gap_is_lower_bound"] is False
    far = _case("cube.ac", IDENTITY, "cube.ac", (np.eye(3), np.array([1.5, 0.0, 0.0])))
    assert classify_collide(far, True, 1e-6)["class"] == "bug"     # 0.5 apart
    assert classify_collide(far, True, 1e-6)["gap_metres"] == 0.5
    assert classify_pairs(far, np.array([[0, 0]]), 1e-6)["class"] == "bug"


def test_gjk_like_engine_within_and_beyond_its_declared_tolerance():
    # an engine that calls bodies within 1e-5 m touching, as GJK stopping at
    # a tolerance does, declaring 1e-6: right at 1e-7, a bug at 5e-6
    apart = [_case("cube.ac", IDENTITY, "cube.ac", (np.eye(3), np.array([1.0 + gap, 0.0, 0.0])))
             for gap in (1e-7, 5e-6, 0.25)]
    engine = GjkLikeCollide(reach=1e-5, distance_tolerance=1e-6)
    result = check_collide_agreement(engine, PoseCases(cases=tuple(apart), seed=0))
    assert (result.cases, result.passed) == (3, 1)          # 0.25 apart: it says apart
    assert result.classes == {"bug": 1, "tolerance": 1}
    seeded = {e["case"]: e for e in result.examples if not e.get("shrunk")}
    assert seeded[0]["class"] == "tolerance"
    assert seeded[0]["gap_metres"] == pytest.approx(1e-7, rel=1e-6)
    assert seeded[1]["class"] == "bug"
    assert seeded[1]["gap_metres"] == pytest.approx(5e-6, rel=1e-6)
    assert result.largest_miss_metres["bug"] == pytest.approx(5e-6, rel=1e-6)


def test_box_excess_is_in_metres():
    # (1, 0, 0) turned a quarter about z is (0, 1, 0); a box that ignores
    # the rotation is (1, 0, 0): 1 m inside the exact box on x and on y
    case = _box_case([[1.0, 0.0, 0.0]], (QUARTER_TURN, np.zeros(3)))
    lo, hi = BoxIgnoresRotation().aabb(case.vertices, case.pose)
    short, wide = box_excess(case, lo, hi)
    assert short.tolist() == [1.0, 1.0, 0.0]
    assert wide.tolist() == [1.0, 1.0, 0.0]
    verdict = classify_box(case, lo, hi, 0, Declarations(distance_tolerance=1e-6))
    assert verdict["class"] == "bug"
    assert verdict["excess_metres"] == 1.0
    # the bound of a coordinate that rounds nothing is a few subnormals: the
    # ratio overflows; the metres say what is wrong
    assert verdict["excess_rounding_bounds"] == math.inf


def test_box_ignoring_rotation_is_a_bug_with_its_excess_in_metres():
    cases = [_box_case([[1.0, 0.0, 0.0], [0.0, 0.5, 0.0]], (QUARTER_TURN, np.array([2.0, 0, 0]))),
             _box_case([[1.0, 2.0, 3.0]], (np.eye(3), np.array([0.5, 0.0, 0.0])))]
    from refsim.conformance.cases_boxes import BoxCases

    result = check_aabb_encloses(BoxIgnoresRotation(), BoxCases(cases=tuple(cases), seed=0))
    assert (result.passed, result.classes) == (1, {"bug": 1})     # no rotation: right
    seeded = [e for e in result.examples if not e.get("shrunk")]
    # exact box x [1.5, 2], y [0, 1]; the engine's x [2, 3], y [0, 0.5]
    assert seeded[0]["excess_metres"] == 0.5
    assert result.largest_miss_metres == {"bug": 0.5}


def test_padded_box_is_loose_within_its_declared_slack():
    from refsim.conformance.cases_boxes import BoxCases

    cases = BoxCases(cases=(_box_case([[1.0, 2.0, 3.0], [-1.0, 0.0, 0.5]],
                                      (QUARTER_TURN, np.array([0.25, 0.0, 0.0]))),), seed=0)
    within = PaddedBox(pad=0.01, box_slack=0.02)
    assert check_aabb_encloses(within, cases).status == "passed"
    tight = check_aabb_tight(within, cases)
    assert tight.classes == {"loose": 1}
    assert tight.examples[-1]["excess_metres"] == pytest.approx(0.01, rel=1e-12)
    assert tight.examples[-1]["box_slack_metres"] == 0.02
    beyond = check_aabb_tight(PaddedBox(pad=0.05, box_slack=0.02), cases)
    assert beyond.classes == {"bug": 1}


class _Declaring:
    name = "declaring"

    def __init__(self, **attributes):
        self.__dict__.update(attributes)


@pytest.mark.parametrize("attributes, phrase", [
    ({"distance_tolerance": -1e-6}, "distance_tolerance must be a finite number of metres >= 0"),
    ({"box_slack": math.inf}, "box_slack must be a finite number of metres >= 0"),
    ({"distance_tolerance": "small"}, "got 'small'"),
    ({"contact_law": ""}, "contact_law must be a non-empty name"),
])
def test_bad_declarations_are_one_clear_error(attributes, phrase):
    with pytest.raises(OptionError) as info:
        declarations(_Declaring(**attributes))
    assert str(info.value).startswith("engine 'declaring': ") and phrase in str(info.value)


def test_declarations_default_to_exact_and_restitution():
    assert declarations(_Declaring()) == Declarations(0.0, 0.0, "restitution")
    assert declarations(_Declaring(distance_tolerance=1e-6, contact_law="hunt-crossley")) == \
        Declarations(1e-6, 0.0, "hunt-crossley")


def test_the_body_classes_are_the_kits():
    # one vocabulary: every class of the body classifier is a kit class, in
    # the kit's order of seriousness, and so is the order of the pair classes
    from refsim.collision.disagreement import BODY_CLASSES, BODY_REASONS, PAIR_SEVERITY
    from refsim.conformance.results import CLASSES

    for order in (BODY_CLASSES, PAIR_SEVERITY):
        assert list(order) == [c for c in CLASSES if c in order]
    assert {kind for kind, _ in BODY_REASONS.values()} == set(BODY_CLASSES)


class _RoundsPoses:
    """Says "collide" everywhere; declares that it applies float32 poses and
    tests no mesh as a solid."""

    name = "rounds-poses"

    def bodies_collide(self, *arrays) -> bool:
        return True

    @staticmethod
    def pose_used(pose):
        return (np.asarray(pose[0], np.float32).astype(np.float64),
                np.asarray(pose[1], np.float32).astype(np.float64))

    @staticmethod
    def is_solid(vertices, faces) -> bool:
        return False


def test_the_kit_reads_the_engines_pose_and_solid_conventions():
    # unit cubes 2**-30 apart along z (float32: sharing a face), and the
    # tetrahedron inside the sphere: the engine's "collide" is its float32
    # pose on the first, and a bug on the second (it tests no mesh as a
    # solid, though it declares nothing else)
    grazing = _case("cube.ac", IDENTITY, "cube.ac",
                    (np.eye(3), np.array([0.0, 0.0, 1.0 + 2.0 ** -30])))
    inside = _case("sphere-2k.ac", IDENTITY, "tetrahedron.ac",
                   (np.eye(3), np.array([0.1, 0.05, 0])))
    result = check_collide_agreement(_RoundsPoses(), PoseCases(cases=(grazing, inside), seed=0))
    seeded = {e["case"]: e for e in result.examples if not e.get("shrunk")}
    assert (seeded[0]["class"], seeded[0]["reason"]) == ("tolerance", "float32 transform")
    assert seeded[0]["gap_metres"] == 2.0 ** -30
    assert (seeded[1]["class"], seeded[1]["reason"]) == ("bug", "containment without solid")
    assert seeded[1]["contained"] is True and seeded[1]["solid_declared"] is False
