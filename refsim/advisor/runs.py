"""One run of a scene at chosen fidelity settings, measured for the advisor
(:mod:`refsim.advisor`): sampled positions, orientations and energy, the
events with their response speeds, and the work the run did.

What: :func:`measure_run` is a sweep task (:mod:`refsim.sweep`): a
module-level function of plain arguments that returns a plain record. It
rebuilds the scene from plain data (:func:`scene_data`, so that a worker
process or a Dask worker needs no file but the models), replaces the four
fidelity choices (:class:`~refsim.advisor.records.Fidelity`: solver, step,
collision level, box update; nothing else), steps a :class:`refsim.Simulation` and records

- every ``every``-th step (a common grid of sample times, so that runs at
  different steps compare at the same instants, never interpolated): the
  bodies' reported positions and orientations and the total mechanical
  energy, computed by :meth:`refsim.Simulation.energy` (the loop's one
  energy formula); and once, each body's radius about its reported
  position (the farthest vertex of its scaled mesh from the mesh origin),
  with which an orientation difference becomes a distance;
- each event of :attr:`refsim.Simulation.events` with its **response
  speed**: the largest change of a point's velocity that the step's contact
  responses made to the body, ``|dv| + r |dw|`` (``dv``, ``dw`` the changes
  of its velocity and angular velocity by the wall and body responses,
  ``r`` its radius), the larger of the two bodies' for a body contact. Two
  runs that respond ``dt`` apart drift apart at up to that speed until the
  later one responds: the advisor turns a time difference into a distance
  with it. A resting contact's response is small (it cancels a step's
  gravity); an impact's is about ``(1 + e)`` times the approach speed;
- the work, in counts that do not depend on the machine: force evaluations
  times bodies (``steps * stages * B``: the solver evaluates the forces of
  all ``B`` bodies ``stages`` times per step), narrow-phase calls (body
  pairs handed to the scene's collision level), box-update vertex visits
  (the linear scan visits every vertex, the incremental walk fewer); and
  the wall time of the whole run, ``repeats`` times (a timing, noisy: the
  advisor reports the median).

A divergence (:class:`refsim.errors.DivergenceError`) is a result, not a
failure: the record keeps the samples before it and says where it happened.

The counts and the response speeds come from :class:`CountingSimulation`,
a subclass that counts in two of the step's stage methods (the narrow phase
and the box update) and copies the velocities in a third (the divergence
check, after the motion and before the contacts), and otherwise leaves the
step untouched, so the trajectory is the simulation's own, bit for bit (a
test checks it against :func:`refsim.simulate`).

Where the compiled loop runs the scene (:attr:`refsim.Simulation.loop`),
the run goes through it a sample at a time, but for the steps that begin
a contact: each is taken by the readable step, for its events' response
speeds (:func:`_sample_interval`). The loop and the readable step give
the same bits, so the record is the same either way (a test compares them
field for field); only the wall time differs.

Cost: the simulation's own (see :mod:`refsim.dynamics.simulation`) times
``repeats``, plus O(B) per step for the velocities before the responses
(on the readable steps), O(B) per sample; on the loop, the steps before
an onset within a sample are taken twice.
"""

from __future__ import annotations

import statistics
import time
from dataclasses import asdict, replace
from pathlib import Path

import numpy as np

from refsim.advisor.records import Fidelity
from refsim.bundled import models_dir
from refsim.dynamics.simulation import BATCH_VERTICES, Simulation
from refsim.dynamics.start import start_kernel
from refsim.errors import DivergenceError, StateError, check_count
from refsim.scenes.loader import SHAPE_KEYS, scene_from_dict
from refsim.scenes.schema import Scene
from refsim.solvers.integrate import whole_steps
from refsim.solvers.methods import SOLVERS


def scene_fidelity(scene: Scene) -> Fidelity:
    """The fidelity choices a scene makes itself."""
    return Fidelity(scene.integration.solver, scene.integration.step, scene.collision.level,
                    scene.collision.aabb)


def with_fidelity(scene: Scene, fidelity: Fidelity, duration: float | None = None) -> Scene:
    """``scene`` with its solver, step, level and box update replaced (and its
    duration, when given); ``StateError`` when the duration is not a whole
    number of the new steps."""
    duration = scene.integration.duration if duration is None else duration
    whole_steps(duration, fidelity.step)
    return replace(
        scene,
        integration=replace(scene.integration, solver=fidelity.solver, step=fidelity.step,
                            duration=duration),
        collision=replace(scene.collision, level=fidelity.level, aabb=fidelity.aabb))


def scene_data(scene: Scene) -> dict:
    """``scene`` as plain data that :func:`refsim.scenes.loader.scene_from_dict`
    turns back into an equal scene: its tables as written by the schema, each
    body's model by its bare name when it is a bundled model (a worker finds
    it in its own installation) and by absolute path otherwise.

    Raises :class:`StateError` for a scene with a ``[particles]`` table (the
    advisor simulates rigid bodies).
    """
    if scene.particles is not None:
        raise StateError("the scene has a [particles] table; refsim advise tunes "
                         "rigid-body scenes (remove [particles], or split the scene)")
    bundled = models_dir().resolve()
    bodies = []
    for body in scene.bodies:
        values = _unset_left_out(asdict(body))
        if body.shape:                       # a shape is rebuilt from its own keys
            del values["model"]
            for key in [k for k in ("size", "radius", "frequency")
                        if SHAPE_KEYS[k] != body.shape]:
                del values[key]
        else:
            model = Path(body.model).resolve()
            values["model"] = model.name if model.parent == bundled else str(model)
            for key in ("shape", "size", "radius", "frequency"):
                del values[key]
        bodies.append(values)
    data = {"world": _unset_left_out(asdict(scene.world)),
            "integration": asdict(scene.integration),
            "collision": asdict(scene.collision), "dynamics": asdict(scene.dynamics),
            "body": bodies}
    if scene.pairs:
        data["pair"] = [_unset_left_out(asdict(p)) for p in scene.pairs]
    return data


def _unset_left_out(values: dict) -> dict:
    """A table's values without the keys left unset (None: the world's
    ``mu``, a body's own coefficients), as a file that does not write them;
    tuples as lists, as TOML reads them."""
    def plain(v):
        return [plain(x) for x in v] if isinstance(v, tuple) else v

    return {k: plain(v) for k, v in values.items() if v is not None}


class CountingSimulation(Simulation):
    """A :class:`refsim.Simulation` that counts its narrow-phase calls and
    box-update vertex visits (attributes ``narrow_phase_calls`` and
    ``box_visits``, totals since construction), and keeps each step's
    velocities before the contact responses (``v_free``, ``w_free``: copies
    taken in the check stage, after the solver and the rotation step).

    Box visits: a body whose box comes from the batched linear scan (meshes
    of at most ``BATCH_VERTICES`` vertices under the loop's default
    ``boxes="auto"``) visits all its vertices; a body with its own tracker
    visits what the tracker reports (``tracker.visits``: all vertices for the
    linear scan, the walk's for the incremental update).
    """

    def __init__(self, scene: Scene, kernel: str | None = None):
        super().__init__(scene, kernel=kernel)
        self.narrow_phase_calls = 0
        self.box_visits = 0
        self._batched_visits = sum(b.mesh.n_vertices for b in self.bodies
                                   if b.mesh.n_vertices <= BATCH_VERTICES)
        self._own_trackers = [b.tracker for b in self.bodies
                              if b.mesh.n_vertices > BATCH_VERTICES]

    def _check(self) -> None:
        super()._check()
        self.v_free = self.v.copy()
        self.w_free = self.w.copy()

    def _narrow_phase(self, pairs):
        self.narrow_phase_calls += len(pairs)
        return super()._narrow_phase(pairs)

    def _bounds(self) -> None:
        super()._bounds()
        self.box_visits += self._batched_visits + sum(t.visits for t in self._own_trackers)


def measure_run(*, seed: int, scene: dict, solver: str, step: float, level: str, aabb: str,
                duration: float, every: int, repeats: int = 1) -> dict:
    """Simulate ``scene`` (plain data, :func:`scene_data`) with the given
    fidelity for ``duration`` seconds, ``repeats`` times; return the first
    run's record with every run's wall time.

    ``seed`` is the sweep's and unused: the simulation draws nothing at
    random. ``every``: steps between two samples (the duration must be a
    whole number of samples).

    Returns
    -------
    dict
        ``t`` (S,) sample times; ``position`` (S, B, 3) reported positions;
        ``orientation`` (S, B, 3, 3); ``radius`` (B,) m; ``energy`` (S,)
        total mechanical energy in J; ``events``: one
        ``[kind, body, other, step, time, speed]`` per event (the response
        speed in m/s, see the module docstring); ``steps`` taken; ``bodies``;
        ``force_evaluations`` (times bodies), ``narrow_phase_calls``,
        ``box_visits``; ``diverged``: None, or ``{"step", "time",
        "message"}``; ``wall_seconds``: one per repeat (timings).
    """
    del seed
    every = check_count("every", every, minimum=1)
    repeats = check_count("repeats", repeats, minimum=1)
    fidelity = Fidelity(solver, float(step), level, aabb)
    run_scene = with_fidelity(scene_from_dict(scene), fidelity, duration)
    n_steps = run_scene.integration.n_steps
    if n_steps % every:
        raise StateError(f"{n_steps} steps are not a whole number of samples of {every} steps")
    record: dict | None = None
    seconds: list[float] = []
    for _ in range(repeats):
        start = time.perf_counter()
        result = _run(run_scene, n_steps, every)
        seconds.append(time.perf_counter() - start)
        if record is None:
            record = result
    assert record is not None, "repeats >= 1 (checked above): the loop ran"
    record["wall_seconds"] = seconds
    return record


def _run(scene: Scene, n_steps: int, every: int, kernel: str | None = "start") -> dict:
    """One simulation, sampled every ``every`` steps (see :func:`measure_run`).

    ``kernel``: the simulation's (:class:`refsim.Simulation`); "start", the
    default, asks :func:`refsim.dynamics.start.start_kernel` (a short run
    does not wait for the loop's compile). On the compiled loop the run
    goes a sample at a time through :func:`_sample_interval`; else one
    :meth:`~refsim.Simulation.step` at a time. The record is the same,
    field for field, either way (but ``wall_seconds``).
    """
    if kernel == "start":
        kernel = start_kernel(scene, n_steps)
    sim = CountingSimulation(scene, kernel=kernel)
    B = len(sim.bodies)
    index = {name: i for i, name in enumerate(sim.names)}
    samples = n_steps // every + 1
    t = np.empty(samples)
    position = np.empty((samples, B, 3))
    orientation = np.empty((samples, B, 3, 3))
    energy = np.empty(samples)
    events: list[list] = []  # [kind, body, other, step, time, speed], see _note_events
    # the farthest vertex from the reported position (the mesh origin), per body
    radius = [float(np.sqrt((b.mesh.vertices ** 2).sum(axis=1)).max()) for b in sim.bodies]

    def sample(j: int) -> None:
        t[j] = sim.t
        position[j] = sim.position
        orientation[j] = sim.R
        energy[j] = sim.energy().sum()

    def steps(count: int) -> None:
        for _ in range(count):
            seen = len(sim.events)
            sim.step()
            if len(sim.events) > seen:
                _note_events(sim, seen, radius, index, events)

    # the loop counts no box visits of a tracker: such runs take the steps
    in_loop = sim.loop is None and not sim.tracked
    sample(0)
    taken = 1
    diverged = None
    try:
        # overflow on the way to a divergence is reported by the loop's
        # check stage; numpy's own warnings of it are silenced (as in Simulation.run)
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            while sim.steps < n_steps:
                if in_loop:
                    _sample_interval(sim, every, steps)
                else:
                    steps(every)
                sample(taken)
                taken += 1
    except DivergenceError as exc:
        diverged = {"step": exc.step, "time": exc.time, "message": exc.message}
    stages = SOLVERS[scene.integration.solver].stages
    return {
        "t": t[:taken], "position": position[:taken], "orientation": orientation[:taken],
        "radius": radius, "energy": energy[:taken],
        "events": events, "steps": sim.steps, "bodies": B,
        "force_evaluations": sim.steps * stages * B,
        "narrow_phase_calls": sim.narrow_phase_calls, "box_visits": sim.box_visits,
        "diverged": diverged,
    }


def _sample_interval(sim: CountingSimulation, count: int, steps) -> None:
    """``count`` steps of ``sim``: on the compiled loop
    (:meth:`~refsim.Simulation.advance`), but for each step that begins a
    contact, taken by ``steps(1)`` (one readable
    :meth:`~refsim.Simulation.step`, which notes the events' response
    speeds: the velocities before the responses are seen in the check
    stage of a readable step only).

    The loop does not know beforehand which step begins a contact: it runs
    to the end of the interval, and when a contact began, the simulation
    goes back to where it was (:meth:`~refsim.Simulation.restore`), runs
    the loop again up to the step before the first onset, takes that step
    readable, and goes on from there. A divergence sends the rest of the
    interval to ``steps``, which raises it at the same step. The loop and
    the readable step give the same bits, so the steps taken again repeat
    the same trajectory.

    The counts: the loop's steps visit every vertex of the batched bodies
    (the run has no tracker: :func:`_run`); a loop step whose boxes overlap
    runs its narrow phase through ``sim._narrow_phase`` (the loop's body
    stage, :meth:`refsim.dynamics.compiled_loop.CompiledLoop.body_stage`),
    which counts its calls as a readable step's does.
    """
    end = sim.steps + count

    def advance(n: int) -> None:
        looped = sim.loop_steps
        sim.advance(n)
        sim.box_visits += sim._batched_visits * (sim.loop_steps - looped)

    while sim.steps < end:
        start = sim.snapshot()
        seen, calls, visits = len(sim.events), sim.narrow_phase_calls, sim.box_visits
        try:
            advance(end - sim.steps)
            if len(sim.events) == seen:
                return
            onset = sim.events[seen].step            # the steps count after that step
        except DivergenceError:
            onset = None
        sim.restore(start)
        sim.narrow_phase_calls, sim.box_visits = calls, visits
        if onset is None:
            steps(end - sim.steps)
            return
        if onset - 1 > sim.steps:
            advance(onset - 1 - sim.steps)           # no contact begins before the onset
        steps(1)


def _note_events(sim: CountingSimulation, seen: int, radius: list, index: dict,
                 events: list) -> None:
    """Append the step's new events (``sim.events[seen:]``) with their
    response speeds: ``|dv| + r |dw|`` of each body by the step's contact
    responses; the larger of the two bodies' for a body contact."""
    dv, dw = sim.v - sim.v_free, sim.w - sim.w_free
    speed = (np.sqrt((dv * dv).sum(axis=1))
             + np.asarray(radius) * np.sqrt((dw * dw).sum(axis=1)))
    for event in sim.events[seen:]:
        a = index[event.body]
        u = speed[a] if event.kind == "wall" else max(speed[a], speed[index[event.other]])
        events.append([event.kind, event.body, event.other, event.step, event.time, float(u)])


def median_seconds(record: dict) -> float:
    """The median of a record's wall times (a timing)."""
    return float(statistics.median(record["wall_seconds"]))
