"""Speed of the particle system (S10) against the streaming rate of the same
memory, at N = 1e3, 1e5, 1e6, for Euler and RK4.

One benchmark round is one step of the whole system. The streaming baseline
(``refsim.studies.particles.streaming_step``) is ``x += h v`` done with
numpy's in-place ``multiply(v, h, out=scratch)`` and ``add(x, scratch,
out=x)`` over the system's own (N, 3) arrays: 5 x 24 N bytes moved, the
least any step can move. ``make bench`` reports min / median / max per
group (one group per N); divide N by the time for particle-steps per
second, and each case also stores that figure in ``extra_info``.
``refsim.studies.particles.measure_throughput`` gives the same ratio as
numbers for the report. No timing asserts: each benchmark checks the state
it stepped.

With ``--benchmark-disable`` (``make test``) each function runs once: the
N = 1e6 cases then cost one step each (tens of milliseconds) plus building
the system.
"""

from __future__ import annotations

import numpy as np
import pytest

from refsim.particles.config import ParticleConfig
from refsim.particles.system import ParticleSystem
from refsim.studies.particles import STREAMING_BYTES_PER_PARTICLE, streaming_step

COUNTS = (1_000, 100_000, 1_000_000)


def make_system(count: int, solver: str) -> ParticleSystem:
    return ParticleSystem(ParticleConfig(count=count, solver=solver, drag=0.1, step=1e-3))


def record_rate(benchmark, count: int, bytes_per_particle: int | None = None) -> None:
    stats = getattr(benchmark, "stats", None)
    if stats is None:                      # --benchmark-disable: nothing was timed
        return
    best = stats.stats.min
    benchmark.extra_info["particle_steps_per_s"] = count / best
    if bytes_per_particle is not None:
        benchmark.extra_info["bytes_per_s"] = count * bytes_per_particle / best


@pytest.mark.parametrize("count", COUNTS)
@pytest.mark.parametrize("solver", ["euler", "rk4"])
def test_particle_step(benchmark, count, solver):
    benchmark.group = f"particles N={count:.0e}"
    system = make_system(count, solver)
    benchmark(system.step)
    record_rate(benchmark, count)
    assert system.steps >= 1 and system.nfev == system.steps * system.method.stages
    assert np.isfinite(system.state.max()) and np.isfinite(system.state.min())


@pytest.mark.parametrize("count", COUNTS)
def test_streaming_baseline(benchmark, count):
    benchmark.group = f"particles N={count:.0e}"
    system = make_system(count, "euler")
    x, v = system.positions, system.velocities
    x0, v0 = x.copy(), v.copy()
    scratch = np.empty_like(x)
    h = 1e-9
    calls = 0

    def stream():
        nonlocal calls
        calls += 1
        streaming_step(x, v, scratch, h)

    benchmark(stream)
    record_rate(benchmark, count, STREAMING_BYTES_PER_PARTICLE)
    # Repeated exact additions of the same h v (in floating point, one at a
    # time): compare against doing them in a plain loop on the copies.
    for _ in range(calls):
        x0 += h * v0
    np.testing.assert_array_equal(x, x0)
    np.testing.assert_array_equal(v, v0)
