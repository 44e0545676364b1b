"""The solver records the report's entries take from refsim.studies.solvers:
the order conditions each tableau fails, and the stability regions, one per
distinct R(z)."""

from __future__ import annotations

import numpy as np

from refsim.solvers.methods import SOLVERS
from refsim.solvers.stability import stability_grid
from refsim.studies.solvers import failing_order_conditions, stability_regions


def test_failing_order_conditions():
    failing = {k: failing_order_conditions(s) for k, s in SOLVERS.items()}
    # the seed's "backwards Euler" is second order in its words, first in its tableau
    assert failing["backwards-euler"] == ["sum b_i c_i = 1, not 1/2"]
    assert all(not v for k, v in failing.items() if k != "backwards-euler")


def test_stability_regions_share_one_per_polynomial():
    polynomials, x, y, regions = stability_regions((-3.0, 1.0), (-2.0, 2.0), 9)
    assert set(polynomials) == set(SOLVERS)
    assert [label for label, _ in regions] == ["euler", "averaged-euler = midpoint (same R)",
                                               "backwards-euler", "rk4"]
    gx, gy, euler = stability_grid(SOLVERS["euler"], re=(-3.0, 1.0), im=(-2.0, 2.0), n=9)
    np.testing.assert_array_equal(x, gx)
    np.testing.assert_array_equal(y, gy)
    np.testing.assert_array_equal(regions[0][1], euler)
