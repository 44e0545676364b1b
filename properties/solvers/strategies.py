"""Hypothesis strategies of the solver and particle properties (refsim.solvers,
refsim.particles; seeds S6, S10)."""

from __future__ import annotations

import numpy as _np
from hypothesis import strategies as _st

# ===========================================================================
# Solvers and particles (refsim.solvers, refsim.particles; seed S6, S10)
# ===========================================================================
# Linear test equations y' = lambda y with h lambda in a disc where every
# solver's R(z) is O(1), so a step's rounding is a few ulps of |y|; and small
# particle systems with configs drawn across every option.

SOLVER_NAMES = _st.sampled_from(["euler", "averaged-euler", "backwards-euler", "midpoint",
                                 "rk4"])

#: Components of h lambda: |z| <= 3 keeps |R(z)| <= ~20 for rk4.
_Z_COMPONENT = _st.floats(min_value=-2.0, max_value=2.0, allow_nan=False,
                          allow_subnormal=False)

STEP_SIZES = _st.floats(min_value=1e-3, max_value=0.5, allow_nan=False)


@_st.composite
def linear_test_equations(draw):
    """``(lam, h, y0)``: complex ``lam``, step ``h`` and a complex (d,) ``y0``,
    ``d`` in 1..4, with ``|Re(h lam)|, |Im(h lam)| <= 2``."""
    h = draw(STEP_SIZES)
    z = complex(draw(_Z_COMPONENT), draw(_Z_COMPONENT))
    d = draw(_st.integers(min_value=1, max_value=4))
    parts = _st.floats(min_value=-10.0, max_value=10.0, allow_subnormal=False)
    y0 = _np.array([complex(draw(parts), draw(parts)) for _ in range(d)])
    return z / h, h, y0


@_st.composite
def particle_configs(draw, max_count: int = 30):
    """A small :class:`refsim.particles.config.ParticleConfig` over every
    solver, drag model and wall setting; the cube is small enough that
    particles reach its walls within a few steps."""
    from refsim.particles.config import ParticleConfig

    half_size = draw(_st.floats(min_value=0.5, max_value=3.0))
    return ParticleConfig(
        count=draw(_st.integers(min_value=1, max_value=max_count)),
        seed=draw(_st.integers(min_value=0, max_value=2**31 - 1)),
        box_lo=(-half_size,) * 3, box_hi=(half_size,) * 3,
        speed_min=0.0, speed_max=draw(_st.floats(min_value=0.0, max_value=20.0)),
        gravity=draw(_st.floats(min_value=0.0, max_value=20.0)),
        drag=draw(_st.floats(min_value=0.0, max_value=2.0)),
        drag_model=draw(_st.sampled_from(["linear", "quadratic"])),
        mass=draw(_st.floats(min_value=0.1, max_value=10.0)),
        restitution=draw(_st.floats(min_value=0.0, max_value=1.0)),
        friction=draw(_st.floats(min_value=0.0, max_value=1.0)),
        half_size=half_size,
        walls=draw(_st.booleans()),
        solver=draw(SOLVER_NAMES),
        step=draw(_st.floats(min_value=1e-4, max_value=0.05)),
    )
