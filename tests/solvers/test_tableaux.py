"""The tableaux of the seed's solvers (S6): shape, consistency, derived order."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest

import refsim
from refsim.solvers.explicit_rk import ExplicitRungeKutta
from refsim.solvers.methods import RK4_SEED_LITERAL, SEED_LITERAL_VARIANTS, SOLVERS

#: The orders derived from the order conditions (HNW I, table II.2.2).
DERIVED_ORDER = {"euler": 1, "averaged-euler": 2, "backwards-euler": 1, "midpoint": 2, "rk4": 4}

#: The orders the seed states (claim C10); backwards-euler is where they differ.
SEED_ORDER = {"euler": 1, "averaged-euler": 2, "backwards-euler": 2, "midpoint": 2, "rk4": 4}

STAGES = {"euler": 1, "averaged-euler": 2, "backwards-euler": 2, "midpoint": 2, "rk4": 4}


def test_public_solver_keys():
    assert set(refsim.SOLVERS) == {"euler", "averaged-euler", "backwards-euler", "midpoint",
                                   "rk4"}
    assert set(refsim.SEED_LITERAL_VARIANTS) == {"rk4-seed-literal"}


@pytest.mark.parametrize("name", sorted(SOLVERS))
def test_weights_sum_to_one(name):
    assert sum(SOLVERS[name].b) == 1


@pytest.mark.parametrize("name", sorted(SOLVERS) + sorted(SEED_LITERAL_VARIANTS))
def test_row_sums_of_A_are_c(name):
    method = SOLVERS.get(name) or SEED_LITERAL_VARIANTS[name]
    assert method.row_sums() == method.c


@pytest.mark.parametrize("name", sorted(SOLVERS))
def test_derived_order_stages_and_seed_claim(name):
    method = SOLVERS[name]
    assert method.order == DERIVED_ORDER[name]
    assert method.stages == STAGES[name]
    assert method.seed_order == SEED_ORDER[name]
    assert method.seed_text                     # every method quotes the seed


def test_backwards_euler_is_first_order_because_sum_bc_is_one():
    conditions = {name: (value, want)
                  for _, name, value, want in SOLVERS["backwards-euler"].order_conditions()}
    assert conditions["sum b_i = 1"] == (1, 1)
    assert conditions["sum b_i c_i = 1/2"] == (Fraction(1), Fraction(1, 2))


def test_backwards_euler_tableau_evaluates_k2_at_t_plus_h():
    method = SOLVERS["backwards-euler"]
    assert method.c == (0, 1)
    assert method.A == ((0, 0), (1, 0))
    assert method.b == (0, 1)


def test_rk4_classical_weights_and_seed_literal_typo():
    assert SOLVERS["rk4"].b == tuple(Fraction(x) for x in ("1/6", "1/3", "1/3", "1/6"))
    assert RK4_SEED_LITERAL.b == tuple(Fraction(x) for x in ("1/6", "2/3", "2/3", "1/6"))
    assert sum(RK4_SEED_LITERAL.b) == Fraction(5, 3)
    assert RK4_SEED_LITERAL.order == 0          # inconsistent


def test_float_tableau_is_read_only_and_matches_fractions():
    rk4 = SOLVERS["rk4"]
    assert rk4.A_.dtype == np.float64
    np.testing.assert_array_equal(rk4.b_, [1 / 6, 1 / 3, 1 / 3, 1 / 6])
    with pytest.raises(ValueError):
        rk4.b_[0] = 1.0


def test_tableau_must_be_strictly_lower_triangular():
    with pytest.raises(ValueError):
        ExplicitRungeKutta(name="implicit", A=[[1]], b=[1], c=[1])


def test_mismatched_c_gives_order_zero():
    # k2 at t0 instead of t0 + h: c != row sums of A.
    wrong_time = ExplicitRungeKutta(name="x", A=[[0, 0], [1, 0]], b=[0, 1], c=[0, 0])
    assert wrong_time.order == 0
