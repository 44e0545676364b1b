"""The fused step (one compiled loop, many steps per call) gives the readable
step's bits, for every solver, drag law and wall law."""

from __future__ import annotations

import pytest

from refsim.errors import OptionError
from refsim.particles.config import ParticleConfig
from refsim.particles.system import ParticleSystem, _choose_kernel, fused_tableau
from refsim.solvers.explicit_rk import ExplicitRungeKutta
from refsim.solvers.methods import SEED_LITERAL_VARIANTS, SOLVERS

#: The seed's five solvers and its literal RK4 reading.
FUSED_SOLVERS = sorted(SOLVERS) + sorted(SEED_LITERAL_VARIANTS)


def walled(solver, drag_model="linear", walls=True, wall_speed="wall", seed=4, count=2000):
    """A small cube and fast particles: most steps hit a wall somewhere, many
    particles hit two walls (an edge) in one step. 2000 particles are four
    blocks of the fused loop, the last one partial."""
    return ParticleConfig(count=count, seed=seed, solver=solver, step=0.01, drag=0.7,
                          drag_model=drag_model, restitution=0.6, friction=0.3,
                          half_size=0.5, speed_min=5.0, speed_max=40.0, walls=walls,
                          wall_speed=wall_speed, box_lo=(-0.5, -0.5, -0.5),
                          box_hi=(0.5, 0.5, 0.5))


def assert_same(fused, readable):
    assert fused.state.tobytes() == readable.state.tobytes()     # bit for bit, signs of zero too
    assert (fused.bounces, fused.steps, fused.nfev, fused.t) == \
        (readable.bounces, readable.steps, readable.nfev, readable.t)


@pytest.mark.parametrize("wall_speed", ["wall", "seed"])
@pytest.mark.parametrize("drag_model", ["linear", "quadratic"])
@pytest.mark.parametrize("walls", [True, False])
@pytest.mark.parametrize("solver", FUSED_SOLVERS)
def test_fused_step_equals_readable_bit_for_bit(solver, drag_model, walls, wall_speed):
    config = walled(solver, drag_model, walls, wall_speed)
    fused = ParticleSystem(config, kernel="compiled")
    readable = ParticleSystem(config, kernel="readable")
    for _ in range(60):
        fused.step()
        readable.step()
    assert_same(fused, readable)
    assert (fused.bounces > 1000) == walls


@pytest.mark.parametrize("drag_model", ["linear", "quadratic"])
@pytest.mark.parametrize("solver", FUSED_SOLVERS)
@pytest.mark.parametrize("seed", [0, 7])
def test_many_steps_per_call_equal_readable_steps(solver, drag_model, seed):
    # run(): the fused loop takes each block through all 45 steps in one call
    config = walled(solver, drag_model, seed=seed, count=1537)
    fused = ParticleSystem(config, kernel="compiled")
    readable = ParticleSystem(config, kernel="readable")
    fused.run(45)
    readable.run(45)
    assert_same(fused, readable)
    assert fused.bounces > 1000


def test_default_world_and_a_resting_floor():
    # the default cube, gravity and drag: particles fall onto the floor and
    # bounce there for 2000 steps (the wall speed's clamp at 0 comes into play)
    config = ParticleConfig(count=700, seed=3, solver="rk4", drag=0.2, restitution=0.3,
                            step=0.005, speed_max=1.0, box_lo=(-5.0, -5.0, -5.0),
                            box_hi=(5.0, -4.0, 5.0))
    fused = ParticleSystem(config, kernel="compiled")
    readable = ParticleSystem(config, kernel="readable")
    fused.run(2000)
    readable.run(2000)
    assert_same(fused, readable)
    assert readable.bounces > 10_000


@pytest.mark.filterwarnings("ignore::RuntimeWarning")
@pytest.mark.parametrize("solver", ["euler", "rk4"])
def test_a_diverging_run_diverges_the_same(solver):
    from refsim.errors import DivergenceError

    config = ParticleConfig(count=30, drag=100.0, walls=False, solver=solver, step=0.1)
    systems = [ParticleSystem(config, kernel=k) for k in ("compiled", "readable")]
    for system in systems:
        with pytest.raises(DivergenceError):
            system.run(400)
    fused, readable = systems
    assert fused.state.tobytes() == readable.state.tobytes()     # the same bits, NaN included
    assert (fused.steps, fused.t) == (readable.steps, readable.t)


def test_fused_tableau_of_each_solver():
    h = 0.01
    hA, hb, b_used = fused_tableau(SOLVERS["rk4"], h)
    assert list(hA) == [0.0, h * 0.5, h * 0.5, h * 1.0]
    assert list(hb) == [h * (1 / 6), h * (1 / 3), h * (1 / 3), h * (1 / 6)]
    assert list(b_used) == [True] * 4
    _, hb, b_used = fused_tableau(SOLVERS["midpoint"], h)
    assert list(hb) == [0.0, h] and list(b_used) == [False, True]
    # three stages, or A beyond its subdiagonal, are not the fused loop's shape,
    # and the compiled kernel refuses them by name
    ralston3 = ExplicitRungeKutta("three", A=[[0, 0, 0], ["1/2", 0, 0], [0, "3/4", 0]],
                                  b=["2/9", "1/3", "4/9"], c=[0, "1/2", "3/4"])
    assert fused_tableau(ralston3, h) is None
    heun4 = ExplicitRungeKutta("rk4-3/8", A=[[0, 0, 0, 0], ["1/3", 0, 0, 0],
                                             ["-1/3", 1, 0, 0], [1, -1, 1, 0]],
                               b=["1/8", "3/8", "3/8", "1/8"], c=[0, "1/3", "2/3", 1])
    assert fused_tableau(heun4, h) is None
    with pytest.raises(OptionError, match="'rk4-3/8'"):
        _choose_kernel("compiled", heun4)
    assert _choose_kernel(None, heun4) == "readable"


@pytest.mark.parametrize("solver", sorted(SOLVERS))
def test_kernel_choice(solver):
    config = ParticleConfig(count=10, solver=solver)
    assert ParticleSystem(config).kernel == "compiled"          # numba is installed here
    assert ParticleSystem(config, kernel="readable").kernel == "readable"
    with pytest.raises(OptionError, match="kernel must be"):
        ParticleSystem(config, kernel="cuda")
