"""Laws of the particle system (refsim.particles): the fast step is the
plain step to the bit; walls keep every particle in the cube; a bounce keeps
e times the normal speed."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from properties.solvers.strategies import particle_configs
from refsim.dynamics.walls import wall_response_points
from refsim.particles.system import ParticleSystem, plain_step


@settings(max_examples=50)
@given(particle_configs(), st.integers(min_value=1, max_value=8))
def test_fast_step_is_plain_step_bit_for_bit(config, steps):
    system = ParticleSystem(config)
    x, v = system.positions.copy(), system.velocities.copy()
    for _ in range(steps):
        system.step()
        x, v = plain_step(config, x, v)
    np.testing.assert_array_equal(system.positions, x)
    np.testing.assert_array_equal(system.velocities, v)


@settings(max_examples=50)
@given(particle_configs(), st.integers(min_value=1, max_value=8))
def test_walls_keep_particles_in_the_cube(config, steps):
    system = ParticleSystem(replace(config, walls=True))
    system.run(steps)
    assert np.abs(system.positions).max() <= config.half_size


@given(st.floats(min_value=0.0, max_value=1.0), st.floats(min_value=0.0, max_value=1.0),
       st.floats(min_value=1e-3, max_value=0.5), st.integers(min_value=0, max_value=5),
       st.floats(min_value=-10.0, max_value=10.0), st.floats(min_value=-10.0, max_value=10.0))
def test_one_bounce_scales_normal_by_e_and_lateral_by_k_friction(e, friction, depth, wall,
                                                                  lateral_1, lateral_2):
    axis, sign = divmod(wall, 2)
    sign = 1.0 if sign else -1.0
    x = np.zeros((1, 3))
    x[0, axis] = sign * (1.0 + depth)
    v = np.zeros((1, 3))
    v[0, axis] = sign * 2.0                        # moving outward
    others = [a for a in range(3) if a != axis]
    v[0, others] = lateral_1, lateral_2
    x2, v2, bounces = wall_response_points(x, v, 1.0, e, friction, speed="seed")
    assert bounces == 1
    assert x2[0, axis] == sign * 1.0
    assert v2[0, axis] == -e * v[0, axis]
    np.testing.assert_array_equal(v2[0, others], (1.0 - friction) * v[0, others])
