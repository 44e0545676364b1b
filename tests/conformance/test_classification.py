"""How a disagreement is classified: by exact geometry where the answer is
exact, by a documented law where the engine follows one."""

from __future__ import annotations

import numpy as np

from refsim.conformance.cases_boxes import exact_box, rounding_bound
from refsim.conformance.cases_meshes import PoseCase, _exact_pairs
from refsim.conformance.checks_geometry import (
    _classify_box,
    box_excess,
    classify_collide,
    classify_pairs,
    classify_triangles,
)

IDENTITY = (np.eye(3), np.zeros(3))


def _case(model_a, pose_a, model_b, pose_b, gap=None):
    return PoseCase(model_a, model_b, pose_a, pose_b, "deep", gap,
                    _exact_pairs(model_a, pose_a, model_b, pose_b))


def test_triangle_classes():
    a = np.array([[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]])
    touching = np.array([[0.5, 0.5, 0.0], [0.5, 0.5, 1.0], [1.0, 0.0, 1.0]])   # a vertex on a
    coplanar = np.array([[3.0, 3.0, 0.0], [4.0, 3.0, 0.0], [3.0, 4.0, 0.0]])
    crossing = np.array([[0.5, 0.5, -1.0], [0.5, 0.5, 1.0], [1.0, 0.0, 1.0]])
    assert classify_triangles(a, touching) == "touching"
    assert classify_triangles(a, coplanar) == "coplanar"
    assert classify_triangles(a, crossing) == "bug"     # well conditioned: no excuse


def test_a_body_inside_a_convex_one_is_a_known_divergence():
    # the tetrahedron inside the sphere-2k: no surfaces meet (truth: apart),
    # a solid engine (trimesh's GJK on convex meshes) says they collide
    case = _case("sphere-2k.ac", IDENTITY, "tetrahedron.ac", (np.eye(3), np.array([0.1, 0.05, 0])))
    assert len(case.truth) == 0
    assert classify_collide(case, True) == "known-divergence"


def test_a_grazing_gap_within_the_pose_tolerance_is_tolerance():
    pose_b = (np.eye(3), np.array([1.0 + 1e-9, 0.0, 0.0]))      # cubes 1e-9 apart
    case = _case("cube.ac", IDENTITY, "cube.ac", pose_b, gap=1e-9)
    assert len(case.truth) == 0
    assert classify_collide(case, True) == "tolerance"
    far = _case("cube.ac", IDENTITY, "cube.ac", (np.eye(3), np.array([1.5, 0.0, 0.0])))
    assert classify_collide(far, True) == "bug"                 # 0.5 apart: a bug
    assert classify_pairs(far, np.array([[0, 0]])) == "bug"


def test_touching_faces_missed_are_touching_or_coplanar():
    case = _case("cube.ac", IDENTITY, "cube.ac", (np.eye(3), np.array([1.0, 0.25, 0.0])))
    assert len(case.truth) > 0
    assert classify_collide(case, False) in ("touching", "coplanar")
    assert classify_pairs(case, np.zeros((0, 2), dtype=np.int64)) in ("touching", "coplanar")


def test_box_classes():
    vertices = np.array([[1.0, -1.0, 0.5]])
    pose = (np.eye(3), np.array([1e-9, 0.0, 0.0]))
    from refsim.conformance.cases_boxes import BoxCase

    case = BoxCase(vertices, pose, "near-identity", exact_box(vertices, pose),
                   rounding_bound(vertices, pose))
    lo = hi = vertices[0]                                  # the untransformed box
    short, wide = box_excess(case, lo, hi)
    assert short[0] > 1 and short[1] == short[2] == 0.0
    assert _classify_box(case, float(short.max()), lo, hi) == "tolerance"
    shifted = vertices[0] + np.array([0.1, 0.0, 0.0])
    excess = float(box_excess(case, shifted, shifted)[0].max())
    assert _classify_box(case, excess, shifted, shifted) == "bug"
