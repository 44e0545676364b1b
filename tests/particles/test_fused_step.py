"""The fused Euler step (one compiled loop) gives the generic step's bits."""

from __future__ import annotations

import numpy as np
import pytest

from refsim.errors import OptionError
from refsim.particles.config import ParticleConfig
from refsim.particles.system import ParticleSystem


@pytest.mark.parametrize("wall_speed", ["wall", "seed"])
@pytest.mark.parametrize("drag_model", ["linear", "quadratic"])
@pytest.mark.parametrize("walls", [True, False])
def test_fused_equals_generic_bit_for_bit(drag_model, walls, wall_speed):
    # a small cube and fast particles: most steps hit a wall somewhere,
    # many particles hit two walls (an edge) in one step
    config = ParticleConfig(count=2000, seed=4, solver="euler", step=0.01, drag=0.7,
                            drag_model=drag_model, restitution=0.6, friction=0.3,
                            half_size=0.5, speed_min=5.0, speed_max=40.0, walls=walls,
                            wall_speed=wall_speed,
                            box_lo=(-0.5, -0.5, -0.5), box_hi=(0.5, 0.5, 0.5))
    fused = ParticleSystem(config, kernel="compiled")
    generic = ParticleSystem(config, kernel="readable")
    for _ in range(60):
        fused.step()
        generic.step()
    assert np.array_equal(fused.state, generic.state)
    assert (fused.bounces, fused.steps, fused.nfev, fused.t) == \
        (generic.bounces, generic.steps, generic.nfev, generic.t)
    assert (fused.bounces > 1000) == walls


def test_kernel_choice():
    euler = ParticleConfig(count=10, solver="euler")
    assert ParticleSystem(euler).kernel == "compiled"          # numba is installed here
    assert ParticleSystem(ParticleConfig(count=10, solver="rk4")).kernel == "readable"
    with pytest.raises(OptionError, match="fused Euler step only"):
        ParticleSystem(ParticleConfig(count=10, solver="midpoint"), kernel="compiled")
    with pytest.raises(OptionError, match="kernel must be"):
        ParticleSystem(euler, kernel="cuda")
