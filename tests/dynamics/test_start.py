"""The kernel ``refsim run`` starts on (refsim.dynamics.start): the readable
one for a short run while numba has not compiled the loop, with the same
frames bit for bit; the default otherwise."""

from __future__ import annotations

import os
import re
import subprocess
import sys

import numpy as np
import pytest

from refsim import load_scene
from refsim.bundled import scenes_dir
from refsim.dynamics import start
from refsim.dynamics.compiled_loop import loop_support
from refsim.dynamics.simulate import simulate
from refsim.dynamics.simulation import Simulation

SPIN = scenes_dir() / "spinning-cube.toml"


@pytest.fixture
def cold(monkeypatch):
    """As if numba's cache held no loop for this machine, in a process that
    has spent none of its readable budget, with the tiered start on."""
    monkeypatch.setattr("refsim.kernels.compiled_here", lambda dispatcher: False)
    monkeypatch.delenv("REFSIM_KERNELS", raising=False)
    monkeypatch.delenv("REFSIM_TIERED_START", raising=False)
    monkeypatch.setattr(start.LOOP, "spent", 0.0)
    monkeypatch.setattr(start.LOOP, "settled", False)


def test_a_short_run_starts_readable_when_the_loop_is_not_compiled(cold):
    scene = load_scene(SPIN)
    assert start.start_kernel(scene, scene.integration.n_steps) == "readable"


def test_a_long_run_waits_for_the_compile(cold):
    # 10^8 steps of about 0.1 ms: hours readable, against a compile of seconds
    scene = load_scene(SPIN)
    assert start.start_kernel(scene, 10**8) is None


def test_the_environment_and_the_compiled_loop_decide_first(cold, monkeypatch):
    scene = load_scene(SPIN)
    monkeypatch.setenv("REFSIM_KERNELS", "compiled")
    assert start.start_kernel(scene, scene.integration.n_steps) is None
    assert not start.LOOP.settled              # REFSIM_KERNELS chooses call by call
    monkeypatch.delenv("REFSIM_KERNELS")
    monkeypatch.setenv("REFSIM_TIERED_START", "0")
    assert start.start_kernel(scene, scene.integration.n_steps) is None
    assert start.LOOP.settled                  # the tiered start off: settled
    monkeypatch.delenv("REFSIM_TIERED_START")
    monkeypatch.setattr(start.LOOP, "settled", False)
    monkeypatch.setattr("refsim.kernels.compiled_here", lambda dispatcher: True)
    assert start.start_kernel(scene, scene.integration.n_steps) is None
    assert start.LOOP.settled                  # compiled here: compiled from now on


def test_a_process_runs_readable_until_its_budget_is_spent(cold, monkeypatch):
    # the budget left, not the whole compile time, bounds the next run
    scene = load_scene(SPIN)
    assert start.start_kernel(scene, scene.integration.n_steps) == "readable"
    spent = start.LOOP.spent
    assert 0.0 < spent < start.PROBE_SECONDS + 1.0       # the probe, charged
    monkeypatch.setattr(start.LOOP, "spent", start.LOOP.compile_seconds - 1e-3)
    assert start.start_kernel(scene, scene.integration.n_steps) is None
    assert start.LOOP.settled


def test_simulate_by_default_runs_readable_on_a_cold_cache_with_the_same_frames(cold,
                                                                                monkeypatch):
    chosen = []
    original = Simulation.__init__

    def spy(self, *args, **kwargs):
        original(self, *args, **kwargs)
        chosen.append(self.kernel)

    monkeypatch.setattr(Simulation, "__init__", spy)
    scene = load_scene(SPIN)
    tiered = simulate(scene)
    probe_and_run = start.LOOP.spent
    assert chosen == ["readable", "readable"]            # the probe, then the run
    compiled = simulate(scene, kernel="compiled")
    assert start.LOOP.spent == probe_and_run             # an explicit kernel is not charged
    for name in ("t", "position", "velocity", "angular_velocity", "orientation"):
        assert getattr(tiered, name).tobytes() == getattr(compiled, name).tobytes(), name
    assert tiered.settings["kernel"] == "readable"
    monkeypatch.setattr(start.LOOP, "spent", start.LOOP.compile_seconds)
    simulate(scene, duration=0.01)
    assert chosen[-1] == "compiled"                      # the budget is spent: compiled


def test_a_scene_the_loop_cannot_run_keeps_the_default(cold, tmp_path):
    text = (SPIN.read_text().replace('rotation = "seed"', 'rotation = "impulse"')
            .replace('name = "cube"', 'name = "cube"\ntorque = [0.0, 0.1, 0.0]'))
    path = tmp_path / "torque.toml"
    path.write_text(text)
    scene = load_scene(path)
    assert loop_support(Simulation(scene, kernel="readable")) == "a torque"
    assert start.start_kernel(scene, scene.integration.n_steps) is None


def test_refsim_run_on_an_empty_cache_writes_the_compiled_loops_frames(tmp_path):
    # a fresh numba cache: the run says it starts readable and compiles nothing
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "numba"), REFSIM_COMPILE_NOTICE="1")
    env.pop("REFSIM_KERNELS", None)
    env.pop("REFSIM_TIERED_START", None)
    out = tmp_path / "spin.npz"
    done = subprocess.run([sys.executable, "-m", "refsim.cli", "run", str(SPIN), "-o", str(out)],
                          env=env, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert done.stderr.startswith("refsim: numba has not compiled the simulation loop")
    # besides that notice, at most the progress lines a slow (loaded) machine
    # gets ("refsim run: 879/1001 frames, ..."), and no compile notice
    said = [line for line in done.stderr.splitlines()[1:]
            if not re.fullmatch(r"refsim run: \d+/\d+ frames(, about .* left)?", line)]
    assert "compiling" not in done.stderr and said == []
    compiled = simulate(load_scene(SPIN), kernel="compiled")
    with np.load(out) as written:
        assert '"kernel": "readable"' in str(written["settings"])
        for name in ("t", "position", "velocity", "angular_velocity", "orientation"):
            assert written[name].tobytes() == getattr(compiled, name).tobytes(), name


BIG_MESHES = """
[world]
half_size = 5.0

[integration]
solver = "rk4"
step = 0.001
duration = 0.2

[collision]
level = "exact"

[dynamics]
rotation = "impulse"
body_response = "impulse"
wall_response = "impulse"

[[body]]
name = "a"
model = "sphere-20k.ac"
position = [0.0, 0.0, 0.0]

[[body]]
name = "b"
model = "sphere-20k.ac"
position = [0.0, 2.05, 0.0]
velocity = [0.0, -1.0, 0.0]
"""


def test_large_meshes_that_can_meet_are_not_timed(cold, tmp_path, monkeypatch):
    # the probe would meet the readable build of a 20 000-triangle hierarchy
    path = tmp_path / "big.toml"
    path.write_text(BIG_MESHES)
    scene = load_scene(path)
    assert loop_support(Simulation(scene, kernel="readable")) is None   # the loop could run it

    def no_steps(self, n_steps):
        raise AssertionError("the probe stepped")

    monkeypatch.setattr(Simulation, "advance", no_steps)
    assert start.start_kernel(scene, scene.integration.n_steps) is None


CACHED_LOOP_CHILD = r"""
import json
from refsim.dynamics.simulation import Simulation
from refsim.studies.bounce_scenes import cubes_scene
Simulation(cubes_scene(10, "seed"), kernel="compiled").advance(2)
from refsim.dynamics._numba_kernels import advance
print(json.dumps({"hits": sum(advance.stats.cache_hits.values()),
                  "misses": sum(advance.stats.cache_misses.values())}))
"""


def test_a_second_process_loads_the_loop_from_numbas_cache():
    """The loop has one signature for every scene, and its machine code
    survives the process: once this process has run it (compiling it into
    numba's cache, or loading it from there), a fresh process loads it
    without compiling. (Its cold compile is timed by
    docs/decisions/loop_compile_cost.py, not here.)"""
    from refsim.dynamics._numba_kernels import advance
    from refsim.studies.bounce_scenes import cubes_scene

    Simulation(cubes_scene(3, "impulse"), kernel="compiled").advance(2)
    assert len(advance.signatures) == 1
    env = dict(os.environ)
    env.pop("NUMBA_DISABLE_JIT", None)
    done = subprocess.run([sys.executable, "-c", CACHED_LOOP_CHILD], env=env,
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip().splitlines()[-1] == '{"hits": 1, "misses": 0}'
