"""Speed of the particle system (S10): each solver's step, fused and
readable, at the sizes a user meets (1e3 to 1e6 particles), and at 1e6 each
fused step against its own streaming bound.

``test_particle_step``: one benchmark round is one step of the whole system
(``ParticleSystem.step``), with the compiled (fused) and the readable kernel.
``make bench`` reports min / median / max per group (one group per N); each
case stores particle-steps per second in ``extra_info``.

``test_streaming_bound``: the bytes a step must move are the state read once
and written once (96 bytes a particle); its bound is the time to move them at
the machine's copy rate, measured in the same run: each round times one step
(or one ``run(10)``, ten steps sharing a pass over memory) and, just before
it, one ``np.copyto`` of the state, so a machine busy with other work slows
both alike. ``extra_info`` holds the median step, the median copy (the
bound) and their ratio, ``fraction_of_bound``::

    .venv/bin/python -m pytest tests/benchmarks/test_bench_particles.py -k bound \\
        --benchmark-only --benchmark-json=bound.json -s

prints one line per solver as well. ``refsim.studies.particles.
measure_streaming_bound`` gives the same numbers outside pytest. The
``streaming_step`` baseline (``x += h v`` with numpy's in-place operations,
5 x 24 bytes a particle) is kept for ``measure_throughput``.

No timing asserts: each benchmark checks the state it stepped, the first
particles bit for bit against the readable step (particles do not interact,
so a readable system of those particles alone must end with the same bits).

With ``--benchmark-disable`` (``make test``) each function runs once.
"""

from __future__ import annotations

import time

import numpy as np
import pytest

from refsim.particles.config import ParticleConfig
from refsim.particles.system import ParticleSystem
from refsim.solvers.methods import SOLVERS
from refsim.studies.particles import (
    STEP_BYTES_PER_PARTICLE,
    STREAMING_BYTES_PER_PARTICLE,
    streaming_step,
)

COUNTS = (1_000, 10_000, 100_000, 1_000_000)

#: Particles checked bit for bit against the readable step after a benchmark.
CHECKED = 500


def make_system(count: int, solver: str, kernel: str | None = None) -> ParticleSystem:
    return ParticleSystem(ParticleConfig(count=count, solver=solver, drag=0.1, step=1e-3),
                          kernel=kernel)


def record_rate(benchmark, count: int, bytes_per_particle: int | None = None) -> None:
    stats = getattr(benchmark, "stats", None)
    if stats is None:                      # --benchmark-disable: nothing was timed
        return
    best = stats.stats.min
    benchmark.extra_info["particle_steps_per_s"] = count / best
    if bytes_per_particle is not None:
        benchmark.extra_info["bytes_per_s"] = count * bytes_per_particle / best


def assert_first_particles_readable(system: ParticleSystem) -> None:
    """The first CHECKED particles of ``system`` are those a readable system
    of them alone reaches in as many steps, bit for bit."""
    x0, v0 = system.config.initial_state()
    readable = ParticleSystem(system.config, positions=x0[:CHECKED], velocities=v0[:CHECKED],
                              kernel="readable")
    readable.run(system.steps)
    assert np.array_equal(system.state[:, :CHECKED], readable.state)
    assert system.t == readable.t and system.bounces >= readable.bounces


@pytest.mark.parametrize("count", COUNTS)
@pytest.mark.parametrize("kernel", ["compiled", "readable"])
@pytest.mark.parametrize("solver", sorted(SOLVERS))
def test_particle_step(benchmark, count, solver, kernel):
    benchmark.group = f"particles N={count:.0e}"
    system = make_system(count, solver, kernel)
    system.step()                          # a compiled kernel's load is not timed
    benchmark(system.step)
    record_rate(benchmark, count)
    assert system.steps >= 2 and system.nfev == system.steps * system.method.stages
    assert np.isfinite(system.state.max()) and np.isfinite(system.state.min())
    assert_first_particles_readable(system)


@pytest.mark.parametrize("steps_per_call", [1, 10])
@pytest.mark.parametrize("solver", sorted(SOLVERS))
def test_streaming_bound(benchmark, solver, steps_per_call):
    count = 1_000_000
    benchmark.group = f"particles N=1e+06, fused, against a copy of the state, " \
                      f"{steps_per_call} step(s) a call"
    system = make_system(count, solver, "compiled")
    system.step()
    copy = np.empty_like(system.state)
    copies = []

    def time_a_copy():
        start = time.perf_counter()
        np.copyto(copy, system.state)
        copies.append(time.perf_counter() - start)

    def steps():
        if steps_per_call == 1:
            system.step()
        else:
            system.run(steps_per_call)       # and its check that the state is finite

    benchmark.pedantic(steps, setup=time_a_copy, rounds=21 if steps_per_call == 1 else 11)
    stats = getattr(benchmark, "stats", None)
    if stats is not None:                  # timed (not --benchmark-disable)
        step_s = stats.stats.median / steps_per_call
        copy_s = float(np.median(copies))
        info = {"step_ms": step_s * 1e3, "bound_ms": copy_s * 1e3,
                "copy_bytes_per_s": STEP_BYTES_PER_PARTICLE * count / copy_s,
                "fraction_of_bound": copy_s / step_s}
        benchmark.extra_info.update(info)
        print(f"\n{solver}: fused {info['step_ms']:.2f} ms a step ({steps_per_call} a call), "
              f"bound {info['bound_ms']:.2f} ms, {100 * info['fraction_of_bound']:.0f}% of it")
    assert copies and system.steps >= 1 + steps_per_call
    assert_first_particles_readable(system)


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
