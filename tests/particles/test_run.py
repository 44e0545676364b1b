"""run_particles: the frames of a particle run, in memory or spilled to disk,
the same bit for bit, also when the run diverges."""

from __future__ import annotations

import numpy as np
import pytest

from refsim.errors import DivergenceError
from refsim.particles.config import ParticleConfig
from refsim.particles.run import run_particles
from refsim.particles.system import ParticleSystem
from refsim.storage.frames import SpillSink

CONFIG = ParticleConfig(count=50, seed=11, half_size=1.0, box_lo=(-0.5, -0.5, -0.5),
                        box_hi=(0.5, 0.5, 0.5), speed_min=1.0, speed_max=4.0, drag=0.1,
                        restitution=0.7, friction=0.2, solver="rk4", step=0.01)

#: Quadratic drag k/m = 50 at 5 m/s with Euler at h = 0.1: h k |v| / m = 25,
#: far outside Euler's stability; the speed overflows within ten steps.
DIVERGING = ParticleConfig(count=5, drag=50.0, drag_model="quadratic", solver="euler",
                           step=0.1, speed_min=5.0)


def _same(a, b):
    for name in ("step", "t", "position", "velocity"):
        x, y = np.asarray(getattr(a, name)), np.asarray(getattr(b, name))
        assert x.dtype == y.dtype and x.shape == y.shape, name
        assert np.array_equal(x, y), name


@pytest.mark.parametrize("every", [1, 30])
def test_memory_frames_are_the_systems_states(every):
    frames = run_particles(CONFIG, 100, every)
    expected_steps = list(range(0, 100, every)) + [100]
    assert frames.step.dtype == np.int64 and list(frames.step) == expected_steps
    assert np.array_equal(frames.t, frames.step * CONFIG.step)
    system = ParticleSystem(CONFIG)
    for i, step in enumerate(expected_steps):
        system.run(step - system.steps)
        assert np.array_equal(frames.position[i], system.positions)
        assert np.array_equal(frames.velocity[i], system.velocities)


@pytest.mark.parametrize("every", [1, 30])
def test_spilled_frames_are_the_memory_frames(tmp_path, every):
    kept = run_particles(CONFIG, 100, every)
    with SpillSink(tmp_path / "out.npz") as sink:
        _same(run_particles(CONFIG, 100, every, sink=sink), kept)
    assert list(tmp_path.iterdir()) == []


def test_a_divergence_keeps_the_same_frames_spilled_or_not(tmp_path):
    with pytest.raises(DivergenceError) as memory:
        run_particles(DIVERGING, 100, 3)
    with SpillSink(tmp_path / "out.npz") as sink:
        with pytest.raises(DivergenceError) as spilled:
            run_particles(DIVERGING, 100, 3, sink=sink)
        assert spilled.value.step == memory.value.step
        _same(spilled.value.partial, memory.value.partial)
    partial = memory.value.partial
    # every stored frame is finite, at the stride, and before the divergence
    assert np.isfinite(partial.position).all() and np.isfinite(partial.velocity).all()
    assert list(partial.step) == list(range(0, partial.step[-1] + 1, 3))
    assert 0 < memory.value.step - partial.step[-1] <= 3
