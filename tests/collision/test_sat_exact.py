"""refsim's edge-triangle test against an independent exact algorithm: the
separating axis theorem in rational arithmetic (refsim.collision.sat_exact)."""

from __future__ import annotations

import numpy as np
import pytest

from refsim.collision.sat_exact import triangles_intersect_sat
from refsim.collision.triangle import triangles_intersect
from refsim.studies.triangles import classify_disagreement, near_degenerate_pairs

from .test_triangle import CASES, T


def _pairs():
    rng = np.random.default_rng(31)
    A, B = rng.uniform(-1.0, 1.0, (2, 600, 3, 3))
    yield from zip(A, B, strict=True)
    # small integers: exact touching, coplanar and shared-edge cases by the hundred
    A, B = rng.integers(-2, 3, (2, 1500, 3, 3)).astype(float)
    yield from zip(A, B, strict=True)
    A, B, _ = near_degenerate_pairs(600, seed=32)
    yield from zip(A, B, strict=True)


def test_two_exact_algorithms_agree():
    compared = intersecting = 0
    for a, b in _pairs():
        truth = triangles_intersect_sat(a, b)
        if truth is None:                    # a degenerate triangle: no ground truth
            continue
        assert triangles_intersect(a, b) == truth, (a.tolist(), b.tolist())
        compared += 1
        intersecting += truth
    assert compared > 2500 and 500 < intersecting < compared - 500   # both answers tested


@pytest.mark.parametrize("name", sorted(CASES))
def test_constructed_cases(name):
    other, expected = CASES[name][:2]
    truth = triangles_intersect_sat(np.asarray(T, float), np.asarray(other, float))
    assert truth in (expected, None)


def test_degenerate_triangles_have_no_ground_truth():
    segment = [[0, 0, 0], [1, 0, 0], [2, 0, 0]]
    assert triangles_intersect_sat(segment, T) is None


def test_a_wrong_refsim_answer_is_classified_as_a_bug(monkeypatch):
    # A clean crossing pair (no exact zero, well conditioned): if refsim
    # answered it wrongly, the ground truth must expose it as "bug" even
    # though no margin heuristic would.
    import refsim.studies.triangles as measure

    a = [[0.0, 0.0, -1.0], [1.0, 0.1, 1.0], [0.2, 1.0, 1.0]]
    b = [[-1.0, 0.3, 0.0], [2.0, 0.4, 0.1], [0.5, 2.0, -0.1]]
    assert triangles_intersect_sat(a, b) is True
    monkeypatch.setattr(measure, "triangles_intersect", lambda t1, t2: False)
    assert classify_disagreement(a, b) == "bug"


def _sat_in_fractions(a, b):
    """The same separating-axis test in ``fractions.Fraction`` (how the
    ground truth was first written): the integer scaling must not change a
    single answer."""
    from fractions import Fraction

    from refsim.collision.sat_exact import _cross, _dot, _sub

    A = [tuple(Fraction(float(x)) for x in p) for p in a]
    B = [tuple(Fraction(float(x)) for x in p) for p in b]
    ea = [_sub(A[(i + 1) % 3], A[i]) for i in range(3)]
    eb = [_sub(B[(i + 1) % 3], B[i]) for i in range(3)]
    na, nb = _cross(ea[0], ea[1]), _cross(eb[0], eb[1])
    if not any(na) or not any(nb):
        return None
    axes = [na, nb] + [_cross(e, f) for e in ea for f in eb]
    axes += [_cross(na, e) for e in ea] + [_cross(nb, f) for f in eb]
    for w in axes:
        if any(w):
            pa, pb = [_dot(w, p) for p in A], [_dot(w, p) for p in B]
            if max(pa) < min(pb) or max(pb) < min(pa):
                return False
    return True


def test_integer_scaling_gives_the_rational_answers_on_every_family():
    """600 kit cases (every family: touching, coplanar, grazing, near-parallel
    and the integer grids among them), each pair also scaled by 2^-60 and
    2^60 (denominators and numerators far apart): the same answer as
    rational arithmetic, case by case."""
    from refsim.conformance.cases_triangles import triangle_cases

    for pair in triangle_cases(600, seed=3).pairs:
        for scale in (1.0, 2.0 ** -60, 2.0 ** 60):
            a, b = pair.a * scale, pair.b * scale
            assert triangles_intersect_sat(a, b) == _sat_in_fractions(a, b) == pair.truth


def test_both_classifiers_share_the_exact_classes():
    """The studies' classifier and the conformance kit's give the same class
    wherever exact predicates decide (refsim.collision.disagreement.exact_class)."""
    from refsim.collision.disagreement import EXACT_CLASSES, exact_class
    from refsim.conformance.cases_triangles import triangle_cases
    from refsim.conformance.checks_geometry import classify_triangles

    decided = 0
    for pair in triangle_cases(400, 0).pairs:
        t1 = tuple(map(tuple, np.asarray(pair.a, np.float64).tolist()))
        t2 = tuple(map(tuple, np.asarray(pair.b, np.float64).tolist()))
        kind = exact_class(t1, t2)
        if kind is not None:
            decided += 1
            assert kind in EXACT_CLASSES
            assert classify_disagreement(pair.a, pair.b) == kind
            assert classify_triangles(pair.a, pair.b)["class"] == kind
    assert decided > 0
