"""The particle system: walls, forces, the fast path against the plain one."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from refsim.dynamics.forces import acceleration
from refsim.dynamics.walls import wall_response_points, wall_response_points_inplace
from refsim.errors import DivergenceError, StateError
from refsim.particles.config import ParticleConfig
from refsim.particles.system import ParticleSystem, plain_step
from refsim.solvers.methods import SOLVERS


def one_particle(x, v, **kw):
    config = ParticleConfig(count=1, **kw)
    return ParticleSystem(config, positions=[x], velocities=[v])


@pytest.mark.parametrize("restitution", [0.0, 0.5, 0.8, 1.0])
def test_wall_bounce_leaves_at_e_times_the_speed(restitution):
    # Moving at 3 m/s toward the +x wall, no gravity or drag: one Euler step
    # carries it 0.03 beyond the wall.
    system = one_particle([4.99, 0.0, 0.0], [3.0, 0.0, 0.0], gravity=0.0,
                          restitution=restitution, solver="euler", step=0.01)
    system.step()
    assert system.positions[0, 0] == 5.0                     # pushed back onto the wall
    assert system.velocities[0, 0] == pytest.approx(-restitution * 3.0, rel=1e-15)
    assert system.bounces == 1


def test_friction_scales_the_lateral_components():
    system = one_particle([0.0, -4.995, 0.0], [2.0, -1.0, -4.0], gravity=0.0,
                          restitution=0.5, friction=0.25, solver="euler", step=0.01)
    system.step()
    # The seed's kFriction = 1 - friction on both lateral components.
    np.testing.assert_allclose(system.velocities[0], [1.5, 0.5, -3.0], rtol=1e-15)
    assert system.positions[0, 1] == -5.0


def test_inside_particles_are_untouched_by_walls():
    x = np.array([[0.0, 5.0, 0.0], [-5.0, 0.0, 4.9]])     # on the wall counts as inside
    v = np.ones((2, 3))
    x2, v2, bounces = wall_response_points(x, v, 5.0, 0.8, 0.1, 9.81)
    assert bounces == 0
    np.testing.assert_array_equal(x2, x)
    np.testing.assert_array_equal(v2, v)


@pytest.mark.parametrize("speed", ["wall", "seed"])
@pytest.mark.parametrize("gravity", [0.0, 9.81])
def test_wall_response_inplace_matches_plain(speed, gravity):
    rng = np.random.default_rng(0)
    x = rng.uniform(-1.3, 1.3, (1000, 3))
    v = rng.normal(size=(1000, 3))
    x_plain, v_plain, n_plain = wall_response_points(x, v, 1.0, 0.7, 0.2, gravity, speed)
    n_fast = wall_response_points_inplace(x, v, 1.0, 0.7, 0.2, np.empty(1000, dtype=bool),
                                          gravity, speed, np.empty(1000))
    assert n_fast == n_plain > 0
    np.testing.assert_array_equal(x, x_plain)
    np.testing.assert_array_equal(v, v_plain)


@pytest.mark.parametrize("solver", sorted(SOLVERS))
@pytest.mark.parametrize("drag_model", ["linear", "quadratic"])
def test_fast_step_equals_plain_step_bit_for_bit(solver, drag_model):
    config = ParticleConfig(count=40, seed=5, solver=solver, drag=0.3, drag_model=drag_model,
                            step=0.05, half_size=1.5, friction=0.2)
    system = ParticleSystem(config)
    x, v = system.positions.copy(), system.velocities.copy()
    for _ in range(60):
        system.step()
        x, v = plain_step(config, x, v)
    assert system.bounces > 0
    np.testing.assert_array_equal(system.positions, x)
    np.testing.assert_array_equal(system.velocities, v)


def test_quadratic_drag_force():
    v = np.array([[3.0, 4.0, 0.0]])
    a = acceleration(v, gravity=9.81, drag=0.2, mass=2.0, drag_model="quadratic")
    # -(k/m) |v| v + (0, -g, 0) with |v| = 5
    np.testing.assert_allclose(a, [[-0.1 * 5 * 3, -0.1 * 5 * 4 - 9.81, 0.0]], rtol=1e-15)


@pytest.mark.parametrize("solver", ["averaged-euler", "midpoint", "rk4"])
def test_free_fall_is_exact_for_second_order_methods(solver):
    # Constant acceleration: x is quadratic in t, which methods of order >= 2
    # integrate exactly (up to rounding).
    system = one_particle([0.0, 4.0, 0.0], [1.0, 2.0, 0.0], solver=solver, step=0.01)
    system.run(50)
    t = 0.5
    np.testing.assert_allclose(system.positions[0], [t, 4.0 + 2.0 * t - 9.81 * t * t / 2, 0.0],
                               rtol=0, atol=1e-13)


def test_euler_free_fall_gains_g2h2_over_2_energy_per_step():
    h = 0.01
    system = one_particle([0.0, 4.0, 0.0], [1.0, 2.0, 0.0], solver="euler", step=h)
    e0 = system.kinetic_energy() + system.potential_energy()
    system.run(50)
    e1 = system.kinetic_energy() + system.potential_energy()
    assert e1 - e0 == pytest.approx(50 * 9.81**2 * h * h / 2, rel=1e-9)


@pytest.mark.parametrize("solver", sorted(SOLVERS))
def test_drag_dissipates_energy(solver):
    config = ParticleConfig(count=100, seed=2, drag=0.5, walls=False, solver=solver, step=0.01)
    system = ParticleSystem(config)
    e0 = system.kinetic_energy() + system.potential_energy()
    system.run(100)
    assert system.kinetic_energy() + system.potential_energy() < e0
    assert system.nfev == 100 * SOLVERS[solver].stages
    assert system.t == pytest.approx(1.0)


def test_bad_initial_state():
    config = ParticleConfig(count=1)
    with pytest.raises(StateError):
        ParticleSystem(config, positions=[[0.0, np.nan, 0.0]], velocities=[[0.0, 0.0, 0.0]])
    with pytest.raises(StateError):
        ParticleSystem(config, positions=[[0.0, 0.0]], velocities=[[0.0, 0.0]])
    with pytest.raises(StateError):
        ParticleSystem(config, positions=[[0.0, 0.0, 0.0]])


@pytest.mark.filterwarnings("ignore::RuntimeWarning")
def test_divergence_is_reported():
    # Linear drag k/m = 100 with h = 0.1: Euler multiplies v by -9 per step.
    config = ParticleConfig(count=3, drag=100.0, walls=False, solver="euler", step=0.1)
    system = ParticleSystem(config)
    with pytest.raises(DivergenceError):
        system.run(400)


def test_seed_literal_solver_runs_in_the_particle_system():
    config = replace(ParticleConfig(count=3, walls=False), solver="rk4-seed-literal")
    system = ParticleSystem(config)
    x, v = system.positions.copy(), system.velocities.copy()
    system.run(2)
    for _ in range(2):
        x, v = plain_step(config, x, v)
    assert system.steps == 2 and system.nfev == 8          # four stages a step
    assert np.array_equal(system.positions, x) and np.array_equal(system.velocities, v)


def test_the_wall_speed_law_is_the_bodies_law_for_points():
    # a particle found 0.05 below the floor moving down at 3 m/s under gravity:
    # "seed" flips the speed it has there; "wall" the speed it had at the wall,
    # by the same formula the bodies' wall response uses (wall_speed)
    from refsim.dynamics.walls import wall_speed

    x = np.array([[0.0, -1.05, 0.0]])
    v = np.array([[0.5, -3.0, 0.0]])
    _, v_seed, _ = wall_response_points(x, v, 1.0, 0.8, 0.0, 9.81, "seed")
    _, v_wall, _ = wall_response_points(x, v, 1.0, 0.8, 0.0, 9.81, "wall")
    assert v_seed[0, 1] == -0.8 * -3.0
    assert v_wall[0, 1] == -0.8 * wall_speed(-3.0, -9.81, 0.05)
    # energy along the axis: the speed at the wall is lower by 2 g (0.05)
    assert v_wall[0, 1] == pytest.approx(0.8 * np.sqrt(9.0 - 2 * 9.81 * 0.05), rel=1e-15)
