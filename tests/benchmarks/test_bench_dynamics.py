"""Speed of a simulation step against pybullet on the same scene.

1, 10 and 40 unit cubes on a grid in the world cube with seeded random
velocities (:func:`refsim.studies.bounce.cubes_scene`), collision level
"aabb", rotation "off" and "seed". One benchmark round is one
``Simulation.step()`` (refsim) or one ``stepSimulation`` plus the drag
forces (pybullet, :meth:`oracles.pybullet_adapter.PybulletOracle.step`),
both in the same run; ``make bench`` groups them per scene, so the two
medians side by side give the ratio. The issue's target is refsim at most
2x pybullet at 40 bodies; these benchmarks measure it and assert no timing.
``refsim study dynamics-step-cost`` (or
:func:`refsim.studies.bounce.measure_step_cost`) prints the ratios.

With ``--benchmark-disable`` (``make test``) each function runs one step.
"""

from __future__ import annotations

import numpy as np
import pytest

from refsim.studies.bounce import BENCH_COUNTS, BENCH_ROTATIONS, cubes_scene


@pytest.mark.parametrize("rotation", BENCH_ROTATIONS)
@pytest.mark.parametrize("count", BENCH_COUNTS)
def test_refsim_step(benchmark, count, rotation):
    from refsim.dynamics.simulation import Simulation

    benchmark.group = f"dynamics step: {count} cubes, rotation {rotation}"
    scene = cubes_scene(count, rotation)
    sim = Simulation(scene)
    benchmark(sim.step)
    assert sim.steps >= 1
    assert np.isfinite(sim.x).all() and np.isfinite(sim.v).all()
    assert np.abs(sim.x).max() < scene.world.half_size


@pytest.mark.oracle
@pytest.mark.parametrize("rotation", BENCH_ROTATIONS)
@pytest.mark.parametrize("count", BENCH_COUNTS)
def test_pybullet_step(benchmark, oracle, count, rotation):
    from refsim.oracles.pybullet_adapter import PybulletOracle

    benchmark.group = f"dynamics step: {count} cubes, rotation {rotation}"
    scene = cubes_scene(count, rotation)
    engine = oracle(PybulletOracle)
    with engine:
        engine.load(scene)
        benchmark(engine.step)
        x, v, _, _ = engine.state()
        assert x.shape == (count, 3) and np.isfinite(x).all() and np.isfinite(v).all()
        # Inside the cube (centres at least the inradius from the walls, up to
        # one step of overlap).
        assert np.abs(x).max() < scene.world.half_size
