"""Speed of a simulation step: refsim (readable and compiled) beside pybullet
and MuJoCo, the same scenes in the same run.

Scenes (:func:`refsim.studies.bounce_scenes.bench_scene`): 1, 10 and 40 unit cubes
on a grid with seeded random velocities (:func:`~refsim.studies.bounce_scenes.cubes_scene`,
collision level "aabb", the seed's body response) and one 2000-triangle
sphere (:func:`~refsim.studies.bounce_scenes.sphere_scene`), for rotation "off",
"seed" and "impulse" (pybullet and MuJoCo always rotate: the rotation option
is refsim's, the oracles run the same scene each time).

States, measured separately: "in-flight" is the scene's initial state (the
bodies thrown, the 40 cubes meeting each other); "settled" is each engine's
own state after ``SETTLE_STEPS`` steps of the scene (cubes resting on the
floor and on each other, the sphere at rest). How the state is kept
comparable: each engine takes a snapshot of the state to be measured
(refsim :meth:`~refsim.dynamics.simulation.Simulation.snapshot`, pybullet
``saveState``, MuJoCo ``mj_getState`` with ``mjSTATE_INTEGRATION``, which
includes its warm start) and restores it before every round, outside the
timing (``benchmark.pedantic`` setup), so every round times the same
``STEPS_PER_ROUND`` steps from the same state.

One round is ``STEPS_PER_ROUND`` steps: refsim's ``Simulation.advance`` (the
compiled loop on kernel "compiled" where the scene allows it, else one
readable ``step`` at a time) and the oracles' ``step`` in a Python loop (one
``stepSimulation`` / ``mj_step`` each, plus their drag forces, none here).
Per-step time = round time / ``STEPS_PER_ROUND`` (in ``extra_info``).
``make bench`` groups the four engines per scene, rotation and state; the
medians side by side give the ratios (docs/decisions/compiled-loop.md has
the table and the command). No timing is asserted.

With ``--benchmark-disable`` (``make test``) each function settles for
``QUICK_SETTLE`` steps only and runs one round.
"""

from __future__ import annotations

import numpy as np
import pytest

from refsim.studies.bounce_scenes import BENCH_BODIES, BENCH_ROTATIONS, SETTLE_STEPS, bench_scene

STEPS_PER_ROUND = 100
ROUNDS = 15
#: Settling steps when the benchmark is disabled (the test only runs the path).
QUICK_SETTLE = 20
STATES = ("in-flight", "settled")


class RefsimEngine:
    """refsim's Simulation behind the benchmark's engine calls."""

    def __init__(self, kernel: str):
        self.kernel = kernel

    def load(self, scene) -> None:
        from refsim.dynamics.simulation import Simulation

        self.sim = Simulation(scene, kernel=self.kernel)

    def advance(self, steps: int) -> None:
        self.sim.advance(steps)

    def snapshot(self):
        return self.sim.snapshot()

    def restore(self, snapshot) -> None:
        self.sim.restore(snapshot)

    def positions(self) -> np.ndarray:
        return self.sim.position


class OracleEngine:
    """pybullet or MuJoCo: their adapters' load and step, and their own
    state snapshots."""

    def __init__(self, name: str, factory):
        self.name = name
        self.engine = factory()

    def load(self, scene) -> None:
        self.engine.load(scene)

    def advance(self, steps: int) -> None:
        step = self.engine.step
        for _ in range(steps):
            step()

    def snapshot(self):
        e = self.engine
        if self.name == "pybullet":
            return e.p.saveState(physicsClientId=e.client)
        mj = e.mujoco
        spec = mj.mjtState.mjSTATE_INTEGRATION
        state = np.empty(mj.mj_stateSize(e.model, spec))
        mj.mj_getState(e.model, e.data, state, spec)
        return state

    def restore(self, snapshot) -> None:
        e = self.engine
        if self.name == "pybullet":
            e.p.restoreState(stateId=snapshot, physicsClientId=e.client)
            return
        mj = e.mujoco
        mj.mj_setState(e.model, e.data, snapshot, mj.mjtState.mjSTATE_INTEGRATION)

    def positions(self) -> np.ndarray:
        return self.engine.state()[0]

    def close(self) -> None:
        if self.name == "pybullet":
            self.engine.close()


def _engine(name: str, oracle):
    if name.startswith("refsim"):
        return RefsimEngine(name.split("-")[1])
    if name == "pybullet":
        from refsim.oracles.pybullet_adapter import PybulletOracle

        return OracleEngine(name, lambda: oracle(PybulletOracle))
    from refsim.oracles.mujoco_adapter import MujocoOracle

    return OracleEngine(name, lambda: oracle(MujocoOracle))


@pytest.mark.parametrize("state", STATES)
@pytest.mark.parametrize("rotation", BENCH_ROTATIONS)
@pytest.mark.parametrize("bodies", BENCH_BODIES)
@pytest.mark.parametrize("engine", ["refsim-readable", "refsim-compiled", "pybullet",
                                    "mujoco"])
def test_step(benchmark, oracle, engine, bodies, rotation, state):
    benchmark.group = f"dynamics step: {bodies}, rotation {rotation}, {state}"
    scene, settle = bench_scene(bodies, rotation)
    quick = benchmark.disabled
    runner = _engine(engine, oracle)
    runner.load(scene)
    if engine == "refsim-compiled":
        runner.advance(1)           # the compile (or numba's cache load), untimed
        runner.load(scene)
    if state == "settled":
        runner.advance(QUICK_SETTLE if quick else settle)
    start = runner.snapshot()
    benchmark.extra_info["steps_per_round"] = STEPS_PER_ROUND
    benchmark.extra_info["engine"] = engine
    try:
        benchmark.pedantic(runner.advance, args=(STEPS_PER_ROUND,),
                           setup=lambda: runner.restore(start),
                           rounds=1 if quick else ROUNDS, iterations=1)
        x = runner.positions()
        count = len(scene.bodies)
        assert x.shape == (count, 3) and np.isfinite(x).all()
        # inside the world cube (mesh origins of bodies of radius <= 1)
        assert np.abs(x).max() < scene.world.half_size
        if isinstance(runner, RefsimEngine):
            sim = runner.sim
            assert sim.steps == start["steps"] + STEPS_PER_ROUND
            if engine == "refsim-compiled":       # every rotation model runs the loop
                assert sim.loop is None and sim.loop_steps >= STEPS_PER_ROUND
    finally:
        if isinstance(runner, OracleEngine):
            runner.close()


def _one_step_per_call(runner, steps: int) -> None:
    for _ in range(steps):
        runner.advance(1)


@pytest.mark.parametrize("bodies", ["1 cube", "10 cubes", "sphere-2k"])
@pytest.mark.parametrize("engine", ["refsim-readable", "refsim-compiled", "pybullet",
                                    "mujoco"])
def test_one_step_per_call(benchmark, oracle, engine, bodies):
    # A caller that steps once per call (a control loop, a viewer's frame):
    # refsim pays its per-call cost (signal hold, the kernel's dispatch) at
    # every step, where test_step spreads it over STEPS_PER_ROUND steps.
    # Rotation "impulse", in flight; the group is read by bench_table.py.
    benchmark.group = f"dynamics step: {bodies}, rotation impulse, one step per call"
    scene, _ = bench_scene(bodies, "impulse")
    runner = _engine(engine, oracle)
    runner.load(scene)
    if engine == "refsim-compiled":
        runner.advance(1)           # the compile (or numba's cache load), untimed
        runner.load(scene)
    start = runner.snapshot()
    benchmark.extra_info["steps_per_round"] = STEPS_PER_ROUND
    benchmark.extra_info["engine"] = engine
    try:
        benchmark.pedantic(_one_step_per_call, args=(runner, STEPS_PER_ROUND),
                           setup=lambda: runner.restore(start),
                           rounds=1 if benchmark.disabled else ROUNDS, iterations=1)
        x = runner.positions()
        assert x.shape == (len(scene.bodies), 3) and np.isfinite(x).all()
        if isinstance(runner, RefsimEngine):
            assert runner.sim.steps == start["steps"] + STEPS_PER_ROUND
    finally:
        if isinstance(runner, OracleEngine):
            runner.close()


def test_restore_repeats_the_same_steps_bit_for_bit():
    # what makes the rounds comparable: from a restored snapshot, refsim takes
    # the same steps again, to the bit, on either kernel, in one call or one
    # step per call
    from refsim.dynamics.simulation import Simulation

    scene, _ = bench_scene("10 cubes", "seed")
    for kernel in ("readable", "compiled"):
        sim = Simulation(scene, kernel=kernel)
        sim.advance(500)
        start = sim.snapshot()
        sim.advance(300)
        first = (sim.x.copy(), sim.v.copy(), sim.w.copy(), list(sim.events))
        for one_call in (True, False):       # test_step's rounds, and test_one_step_per_call's
            sim.restore(start)
            if one_call:
                sim.advance(300)
            else:
                for _ in range(300):
                    sim.advance(1)
            assert sim.x.tobytes() == first[0].tobytes()
            assert sim.v.tobytes() == first[1].tobytes()
            assert sim.w.tobytes() == first[2].tobytes()
            assert sim.events == first[3] and len(first[3]) > len(scene.bodies)
            assert sim.steps == start["steps"] + 300


#: The corrected model's body-contact scenes: the cubes of ``bench_scene`` at
#: the exact level with the impulse responses (rotation, bodies and walls),
#: Coulomb mu 0.3, Euler at h = 1e-3 (docs/decisions/body-contact-speed.md).
CONTACT_BODIES = (10, 40)
#: refsim's readable kernel is left out of these scenes: its settling alone
#: takes minutes (the same bits as the compiled kernel, tests/dynamics).
CONTACT_ENGINES = ("refsim-compiled", "pybullet", "mujoco")
#: Steps per round with ``--benchmark-disable``: the test only runs the path.
QUICK_STEPS = 10
#: The "in-flight" state of these scenes: after this many steps the cubes
#: meet each other in the air (the 40 from step 200, the 10 from step 500),
#: before any has settled; from the initial state the first 100 steps would
#: have no body contact.
FLIGHT_STEPS = 500


def contact_scene(count: int):
    """``count`` cubes of :func:`refsim.studies.bounce_scenes.cubes_scene` (the same
    grid, seed and velocities) in the corrected model at the exact level."""
    from dataclasses import replace

    scene = bench_scene(f"{count} cubes", "impulse")[0]
    return replace(
        scene, world=replace(scene.world, mu=0.3),
        integration=replace(scene.integration, solver="euler"),
        collision=replace(scene.collision, level="exact"),
        dynamics=replace(scene.dynamics, rotation="impulse", body_response="impulse",
                         wall_response="impulse"))


@pytest.mark.parametrize("state", STATES)
@pytest.mark.parametrize("bodies", CONTACT_BODIES)
@pytest.mark.parametrize("engine", CONTACT_ENGINES)
def test_body_contact_step(benchmark, oracle, engine, bodies, state):
    benchmark.group = f"body-contact step: {bodies} cubes, corrected model, {state}"
    scene = contact_scene(bodies)
    quick = benchmark.disabled
    steps = QUICK_STEPS if quick else STEPS_PER_ROUND
    runner = _engine(engine, oracle)
    runner.load(scene)
    if engine == "refsim-compiled":
        runner.advance(1)           # the compile (or numba's cache load), untimed
        runner.load(scene)
    if quick:
        runner.advance(QUICK_SETTLE)
    else:
        runner.advance(SETTLE_STEPS["cubes"] if state == "settled" else FLIGHT_STEPS)
    start = runner.snapshot()
    benchmark.extra_info["steps_per_round"] = steps
    benchmark.extra_info["engine"] = engine
    try:
        benchmark.pedantic(runner.advance, args=(steps,), setup=lambda: runner.restore(start),
                           rounds=1 if quick else ROUNDS, iterations=1)
        x = runner.positions()
        assert x.shape == (bodies, 3) and np.isfinite(x).all()
        assert np.abs(x).max() < scene.world.half_size
        if isinstance(runner, RefsimEngine):
            assert runner.sim.steps == start["steps"] + steps
    finally:
        if isinstance(runner, OracleEngine):
            runner.close()
