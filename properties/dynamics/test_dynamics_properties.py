"""Laws of the corrected dynamics (refsim.dynamics): a collision with
restitution <= 1 never adds energy; body-body impulses conserve linear
momentum and angular momentum about a fixed point; and no state, however
wild, becomes non-finite without a DivergenceError."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given

from properties.dynamics.strategies import contact_pairs, random_two_body_scenes, wall_hit_scenes
from refsim.dynamics import impulse
from refsim.dynamics.simulation import Simulation
from refsim.errors import DivergenceError
from refsim.scenes.loader import scene_from_dict

#: Energies and momenta of order 1-100 after a few dozen operations: rounding.
RTOL = 1e-11


def _solve(a, b, p, n, e, mu):
    (ma, Ia, xa, va, wa), (mb, Ib, xb, vb, wb) = a, b
    va, wa, vb, wb = va.copy(), wa.copy(), vb.copy(), wb.copy()
    P = np.empty((1, 4))
    impulse.solve_contacts_python((p - xa)[None], (p - xb)[None], n, 1 / ma,
                                  np.linalg.inv(Ia), va, wa, 1 / mb, np.linalg.inv(Ib), vb,
                                  wb, e, mu, impulse.RESTITUTION_THRESHOLD,
                                  impulse.ITERATIONS, P)
    return va, wa, vb, wb


@given(contact_pairs())
def test_body_impulse_conserves_linear_and_angular_momentum(pair):
    a, b, p, n, e, mu = pair
    (ma, Ia, xa, va, wa), (mb, Ib, xb, vb, wb) = a, b
    va2, wa2, vb2, wb2 = _solve(*pair)
    scale = 1.0 + ma * np.abs(va).max() + mb * np.abs(vb).max()
    assert np.allclose(ma * va2 + mb * vb2, ma * va + mb * vb, rtol=0, atol=RTOL * scale)

    def L(v1, w1, v2, w2):      # about the origin, a fixed point
        return np.cross(xa, ma * v1) + Ia @ w1 + np.cross(xb, mb * v2) + Ib @ w2

    big = scale * (1 + np.abs(xa).max() + np.abs(xb).max()) + np.abs(Ia).max() * (
        1 + np.abs(wa).max()) + np.abs(Ib).max() * (1 + np.abs(wb).max())
    assert np.allclose(L(va2, wa2, vb2, wb2), L(va, wa, vb, wb), rtol=0, atol=RTOL * big)


@given(contact_pairs())
def test_body_impulse_never_adds_kinetic_energy(pair):
    a, b, p, n, e, mu = pair
    (ma, Ia, _, va, wa), (mb, Ib, _, vb, wb) = a, b
    va2, wa2, vb2, wb2 = _solve(*pair)

    def K(v1, w1, v2, w2):
        return 0.5 * (ma * v1 @ v1 + w1 @ Ia @ w1 + mb * v2 @ v2 + w2 @ Ib @ w2)

    before = K(va, wa, vb, wb)
    assert K(va2, wa2, vb2, wb2) <= before * (1 + RTOL) + RTOL


@given(wall_hit_scenes())
def test_wall_bounce_never_adds_mechanical_energy(data):
    scene = scene_from_dict(data)
    sim = Simulation(scene)
    before = sim.energy().sum()
    sim.step()
    assert [e.kind for e in sim.events] == ["wall"]        # the step did hit the floor
    after = sim.energy().sum()
    assert after <= before * (1 + RTOL) + RTOL
    assert sim.lo[0, 1] >= -scene.world.half_size - 1e-12  # pushed back onto the wall


@pytest.mark.filterwarnings("ignore::RuntimeWarning")    # overflow on the way to inf
@given(random_two_body_scenes())
def test_no_non_finite_state_without_divergence_error(data):
    sim = Simulation(scene_from_dict(data))
    try:
        for _ in range(5):
            sim.step()
    except DivergenceError as error:
        assert error.body in ("a", "b") and error.step >= 1
        return
    for array in (sim.x, sim.v, sim.w, sim.R):
        assert np.isfinite(array).all()
