"""The tiered start (refsim.kernels.Tier): on a cold numba cache a default
call runs the readable kernels, charged to its family's budget, and the
compiled ones once the budget is spent; the answers are the same bits
either way. The suite runs with the tier off (conftest.py); these tests turn
it on, and fake a cold cache by making ``compiled_here`` answer False."""

from __future__ import annotations

import io
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import refsim
from refsim.collision import bodies
from refsim.dynamics import start
from refsim.kernels import Tier
from refsim.particles import system as particles
from refsim.types import rotation_about_axis

SPHERE = refsim.load_model("sphere-2k.ac")
POSE = (rotation_about_axis([1, 2, 3], 0.3), np.array([0.0, 1.0, 0.0]))
OTHER = (np.eye(3), np.array([1.5, 0.0, 0.0]))


@pytest.fixture
def cold(monkeypatch):
    """Every family missing from numba's cache, every budget unspent, the
    tiered start on."""
    monkeypatch.setattr("refsim.kernels.compiled_here", lambda dispatcher: False)
    monkeypatch.delenv("REFSIM_KERNELS", raising=False)
    monkeypatch.delenv("REFSIM_TIERED_START", raising=False)
    for tier in (bodies.EXACT_QUERY, start.LOOP, particles.FUSED_STEPS):
        monkeypatch.setattr(tier, "spent", 0.0)
        monkeypatch.setattr(tier, "settled", False)


def test_a_tier_answers_readable_until_its_budget_is_spent(cold):
    tier = Tier("test", ("refsim.collision._numba_build:build_tree",), compile_seconds=1.0)
    assert tier.readable_first() and tier.remaining() == 1.0
    tier.spent = 0.75
    assert tier.readable_first() and tier.remaining() == 0.25
    tier.spent = 1.0
    assert not tier.readable_first() and tier.settled
    tier.spent = 0.0                         # settled stays settled
    assert not tier.readable_first()


def test_a_tier_charges_the_time_of_its_body(cold):
    tier = Tier("test", (), compile_seconds=10.0)
    with tier.charged():
        sum(range(10**5))
    first = tier.spent
    assert first > 0.0
    with pytest.raises(RuntimeError):        # charged even when the body raises
        with tier.charged():
            raise RuntimeError("the call failed")
    assert tier.spent > first


def test_the_environment_and_a_compiled_family_bypass_a_tier(cold, monkeypatch):
    tier = Tier("test", ("refsim.collision._numba_build:build_tree",), compile_seconds=1.0)
    monkeypatch.setenv("REFSIM_KERNELS", "compiled")      # chooses call by call
    assert not tier.readable_first() and not tier.settled
    monkeypatch.delenv("REFSIM_KERNELS")
    assert tier.readable_first()
    monkeypatch.setenv("REFSIM_TIERED_START", "0")        # off: settles the tier
    assert not tier.readable_first() and tier.settled
    monkeypatch.delenv("REFSIM_TIERED_START")
    assert not tier.readable_first()
    tier.settled = False
    monkeypatch.setattr("refsim.kernels.compiled_here", lambda dispatcher: True)
    assert not tier.readable_first() and tier.settled


def _spy_on_the_exact_query(monkeypatch) -> list[str]:
    """The kernel of each exact query made from now on, in order (a spy on
    both sides of the query's two kernel pairs)."""
    kernels: list[str] = []
    for pair in (bodies.EXACT_HIERARCHY_QUERY, bodies.EXACT_HIERARCHY_COLLIDE):
        for side in ("readable", "compiled"):
            original = getattr(pair, side)

            def spy(*args, _original=original, _side=side):
                kernels.append(_side)
                return _original(*args)

            monkeypatch.setattr(pair, f"_{side}", spy)
    return kernels


def test_the_exact_query_runs_readable_then_compiled_with_the_same_answers(cold, monkeypatch):
    kernels = _spy_on_the_exact_query(monkeypatch)
    pairs = refsim.intersecting_pairs(SPHERE, POSE, SPHERE, OTHER)
    touching = refsim.bodies_collide(SPHERE, POSE, SPHERE, OTHER)
    assert kernels == ["readable", "readable"] and bodies.EXACT_QUERY.spent > 0.0
    compiled = refsim.intersecting_pairs(SPHERE, POSE, SPHERE, OTHER, kernel="compiled")
    assert len(pairs) > 0 and pairs.tobytes() == compiled.tobytes() and touching is True
    # the other levels and an explicit kernel are not the tier's
    refsim.bodies_collide(SPHERE, POSE, SPHERE, OTHER, level="aabb")
    assert kernels[-1] == "compiled" and len(kernels) == 3
    monkeypatch.setattr(bodies.EXACT_QUERY, "spent", bodies.EXACT_QUERY.compile_seconds)
    assert refsim.intersecting_pairs(SPHERE, POSE, SPHERE, OTHER).tobytes() == pairs.tobytes()
    assert kernels[-1] == "compiled" and bodies.EXACT_QUERY.settled


def test_a_large_body_takes_the_compiled_query_at_once(cold, monkeypatch):
    kernels = _spy_on_the_exact_query(monkeypatch)
    big = refsim.load_model("sphere-20k.ac")
    assert big.n_faces > bodies.READABLE_FACES
    far = (np.eye(3), np.array([5.0, 0.0, 0.0]))
    assert not refsim.bodies_collide(big, POSE, SPHERE, far)
    assert kernels == ["compiled"] and bodies.EXACT_QUERY.spent == 0.0


def test_a_particle_run_turns_compiled_when_its_budget_is_spent(cold, monkeypatch):
    config = refsim.load_scene("particles.toml").particles
    reference = refsim.ParticleSystem(config, kernel="compiled")
    reference.run(60)
    tiered = refsim.ParticleSystem(config)
    assert tiered.kernel == "readable"
    # a budget of a few readable blocks: the run switches part way
    per_block = particles.READABLE_PARTICLE_STEPS // tiered.count
    tiered.run(per_block)
    assert tiered.kernel == "readable"
    monkeypatch.setattr(particles.FUSED_STEPS, "spent", particles.FUSED_STEPS.compile_seconds)
    tiered.run(60 - per_block)
    assert tiered.kernel == "compiled" and tiered.steps == 60
    assert tiered.state.tobytes() == reference.state.tobytes()
    assert (tiered.t, tiered.bounces, tiered.nfev) == (reference.t, reference.bounces,
                                                        reference.nfev)


README_SNIPPET = Path(__file__).resolve().parents[1] / "README.md"


def test_the_readme_snippet_on_an_empty_cache_compiles_neither_query_nor_loop(tmp_path):
    """The README's first snippet in a fresh process on an empty numba cache:
    the exact query, the simulation loop and the particle step are not
    compiled (their index files are absent from the cache afterwards), so
    the snippet does not wait for them."""
    text = README_SNIPPET.read_text(encoding="utf-8")
    snippet = text.split("```python\n", 1)[1].split("```", 1)[0]
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "numba"))
    env.pop("REFSIM_TIERED_START", None)
    env.pop("REFSIM_KERNELS", None)
    done = subprocess.run([sys.executable, "-c", snippet], env=env, capture_output=True,
                          text=True, timeout=600, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    indexes = {p.name.split("-")[0] for p in (tmp_path / "numba").rglob("*.nbi")}
    for kernel in ("_numba_kernels.exact_query", "_numba_kernels.exact_collide",
                   "_numba_kernels.advance", "_numba_kernels.rk_steps_fused",
                   "_numba_build.build_tree"):
        assert kernel not in indexes, sorted(indexes)
    assert "_numba_kernels.aabb_linear_numba" in indexes     # a small kernel still compiles


def test_warm_compiles_the_cold_families_by_name(cold, monkeypatch):
    from refsim import warm

    assert set(warm.COMPILERS) == {tier.name for tier in warm.tiers()}
    called = []
    for name in warm.COMPILERS:
        monkeypatch.setitem(warm.COMPILERS, name, lambda name=name: called.append(name))
    monkeypatch.setattr(bodies.EXACT_QUERY, "settled", True)      # as if compiled already
    out = io.StringIO()
    assert warm.warm(out) == ["simulation loop", "fused particle steps"] == called
    assert out.getvalue().splitlines() == ["refsim.warm: compiled the simulation loop",
                                           "refsim.warm: compiled the fused particle steps"]


def test_the_particle_compiler_leaves_the_family_compiled():
    from refsim import warm
    from refsim.kernels import compiled_here
    from refsim.particles import _numba_kernels

    warm.COMPILERS["fused particle steps"]()
    assert compiled_here(_numba_kernels.rk_steps_fused)


def test_a_long_command_starts_the_compile_in_the_background_only_when_cold(cold, monkeypatch):
    from refsim import warm

    started = []
    monkeypatch.setattr(warm.subprocess, "Popen", lambda args, **kw: started.append(args))
    err = io.StringIO()
    warm.start_in_background(err)
    assert started == [[sys.executable, "-m", "refsim.warm"]]
    assert err.getvalue().startswith("refsim: compiling kernels for this machine in the "
                                     "background (exact collision query, simulation loop, "
                                     "fused particle steps;")
    monkeypatch.setattr("refsim.kernels.compiled_here", lambda dispatcher: True)
    err = io.StringIO()
    assert warm.start_in_background(err) is None and err.getvalue() == ""
    assert len(started) == 1


def test_a_test_session_compiles_the_cold_families_side_by_side_first(cold, monkeypatch):
    """``compile_side_by_side`` (the suite's first step under pytest-xdist):
    a process per cold family, all started before any is waited for,
    whatever the tiered start's setting; a failed compile is an error, and
    a warm cache starts nothing."""
    from refsim import warm

    monkeypatch.setenv("REFSIM_TIERED_START", "0")
    events = []

    class Child:
        def __init__(self, args, **kwargs):
            self.name = args[-1]
            events.append(("start", args))

        def wait(self):
            events.append(("wait", self.name))
            return 1 if self.name == "fused particle steps" else 0

    monkeypatch.setattr(warm.subprocess, "Popen", Child)
    out = io.StringIO()
    with pytest.raises(RuntimeError, match=r"^refsim.warm: compiling fused particle steps "
                                           r"failed$"):
        warm.compile_side_by_side(out)
    names = [tier.name for tier in warm.tiers()]
    assert events == ([("start", [sys.executable, "-m", "refsim.warm", n]) for n in names]
                      + [("wait", n) for n in names])
    assert out.getvalue() == (f"refsim: compiling {', '.join(names)} for this machine first "
                              "(numba keeps the machine code)\n")
    monkeypatch.setattr("refsim.kernels.compiled_here", lambda dispatcher: True)
    events.clear()
    assert warm.compile_side_by_side(out) == [] and events == []


def test_one_family_compiles_by_name_in_a_process_of_its_own(tmp_path):
    """``python -m refsim.warm NAME`` compiles that family into numba's cache."""
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "numba"))
    done = subprocess.run([sys.executable, "-m", "refsim.warm", "fused particle steps"],
                          env=env, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    indexes = {p.name.split("-")[0] for p in (tmp_path / "numba").rglob("*.nbi")}
    assert "_numba_kernels.rk_steps_fused" in indexes
    assert "_numba_kernels.advance" not in indexes
