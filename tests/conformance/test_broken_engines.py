"""Three deliberately broken engines, each caught by exactly the checks it
should fail, with a minimal failing example (tests/conformance/broken_engines.py)."""

from __future__ import annotations

import numpy as np
import pytest

from refsim.collision.sat_exact import triangles_intersect_sat
from refsim.collision.triangle import triangles_intersect_float
from refsim.conformance import check_engine
from tests.conformance.broken_engines import (
    box_ignores_translation,
    float_triangles,
    rk4_seed_literal,
)

#: The float test errs on a few per cent of the near-degenerate families:
#: 200 pairs (about 130 near-degenerate) meet several such errors.
TRIANGLE_CASES = 200


@pytest.fixture(scope="module")
def float_result():
    return check_engine(float_triangles(), cases=TRIANGLE_CASES, seed=0)


def test_float_triangle_test_fails_agreement_only(float_result):
    assert float_result.failed_checks() == ["triangles.agreement"]
    agreement = float_result.check("triangles.agreement")
    assert agreement.cases == TRIANGLE_CASES
    assert 0 < agreement.failed < 0.1 * TRIANGLE_CASES
    # rounding errors on inputs within rounding of degenerate: never a "bug"
    assert set(agreement.classes) <= {"tolerance", "touching", "coplanar"}
    assert sum(agreement.classes.values()) == agreement.failed
    failed_families = agreement.measured["failed_by_family"]
    assert set(failed_families) <= {"vertex-on-face", "edge-on-edge", "near-parallel"}
    # the ground truth itself is fine: refsim's test agrees with the SAT
    assert float_result.check("triangles.reference").status == "passed"


def test_float_triangle_failure_is_shrunk_to_a_failing_pair(float_result):
    example = float_result.check("triangles.agreement").examples[0]
    assert example["shrunk"] is True
    a, b = np.array(example["a"]), np.array(example["b"])
    truth = triangles_intersect_sat(a, b)
    assert truth is example["truth"]
    assert triangles_intersect_float(a, b) != truth          # it really fails
    # shrunk: Hypothesis simplified the coordinates (zeros and short binary
    # fractions) while the pair still fails
    coordinates = np.concatenate([a.ravel(), b.ravel()])
    assert (coordinates == 0.0).sum() >= 6


def test_seed_literal_rk4_fails_order_only():
    result = check_engine(rk4_seed_literal(), seed=0)
    assert result.failed_checks() == ["ode.order"]
    order = result.check("ode.order")
    assert order.failed == order.cases == 5
    observed = order.measured["observed_orders"]
    # weights summing to 5/3: the error does not fall with h at all
    assert all(abs(p) < 0.2 for p in observed.values()), observed
    assert order.examples[0]["declared_order"] == 4.0
    assert result.check("ode.evaluations").measured["evaluations_per_step"] == 4
    assert result.check("ode.stability").status == "n/a"


def test_box_that_ignores_the_translation_fails_both_box_checks():
    result = check_engine(box_ignores_translation(), cases=60, seed=0)
    assert result.failed_checks() == ["aabb.encloses", "aabb.tight"]
    for key in ("aabb.encloses", "aabb.tight"):
        check = result.check(key)
        assert check.classes["bug"] > 0.5 * check.cases
        minimal = check.examples[0]
        assert minimal["shrunk"] is True
        # one vertex at the origin, no rotation, one coordinate translated
        assert minimal["vertices"] == [[0.0, 0.0, 0.0]]
        assert minimal["R"] == np.eye(3).tolist()
        assert sum(x != 0.0 for x in minimal["t"]) == 1
        assert minimal["lo"] == minimal["hi"] == [0.0, 0.0, 0.0]
        # the excess in metres: the translation the box forgot
        assert minimal["excess_metres"] == max(abs(x) for x in minimal["t"])
        assert check.largest_miss_metres["bug"] == check.measured["largest_excess_metres"]
