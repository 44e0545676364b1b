"""An independent check of the advisor's answer: the recommended settings
and the reference run afresh through the public :func:`refsim.simulate`,
compared here with plain arrays, not with the advisor's numbers or code.

What: :func:`check_advice` re-runs the reference (rk4, level exact, linear
boxes, at the reference's step) and the recommended settings, recording
every step (:class:`refsim.Trajectory`), and measures

- the largest distance between the two runs' bodies at the advisor's
  sample times up to the horizon (what TOL judges), and, for information,
  at every time both runs have a frame (every common step time): ``|dx| +
  r |dR|_F / sqrt(2)`` from the frames' positions and orientations and each
  body's radius about its reference point, computed here from its mesh.
  The every-step figure can exceed TOL for an instant where the two runs
  push a body out of a contact at different steps (a jump of position, see
  :mod:`refsim.advisor.metrics`);
- the impacts: every event of either run up to the horizon whose response
  speed (``|dv| + r |dw|`` between the frames before and after the step
  that found it, which here includes one step of gravity and drag) is at
  least twice the resting speed must have an event of the same kind, body
  and other body in the other run within ``TOL / speed`` seconds (an
  existence test, simpler than the advisor's ordered pairing, and an
  independent one);
- the end energy, from :meth:`refsim.Simulation.energy` with each run's
  last frame put into a simulation of the scene, against the allowance the
  advisor states.

``python -m refsim.advisor.check`` advises every bundled rigid-body scene
at the tolerances given as the report does (one series per scene,
:func:`refsim.advisor.advice.advice_by_tolerance`), checks each answer and
prints one row per answer.

Cost: two simulations recorded at every step (memory: 19 float64 per body
per step of the reference), plus O(steps) to compare.
"""

from __future__ import annotations

import argparse
import math
import time
from dataclasses import dataclass
from math import gcd

import numpy as np

from refsim.advisor.metrics import REST_SPEED
from refsim.advisor.records import Fidelity
from refsim.advisor.runs import with_fidelity
from refsim.dynamics.simulate import simulate
from refsim.dynamics.simulation import Simulation

#: Impacts at least this fast must have a twin (twice the resting speed, as
#: the advisor excuses unpaired events below it).
CHECK_SPEED = 2.0 * REST_SPEED


@dataclass(frozen=True)
class AdviceCheck:
    """The independent check of one advice (lengths in m, energy as a
    fraction of the reference's largest energy; ``*_seconds`` are timings).
    ``meets``: the positions at the sample times, the impacts and the end
    energy are within what the advisor allows."""

    scene: str
    tolerance: float
    horizon: float
    recommended: str
    position_error_steps: float
    position_error_samples: float
    events_equal: bool
    event_note: str
    energy_gap: float
    energy_allowance: float
    meets: bool
    reference_seconds: float
    recommended_seconds: float


def _trajectory(scene, fidelity: Fidelity, duration: float):
    run_scene = with_fidelity(scene, fidelity, duration)
    start = time.perf_counter()
    # the scene's own wall speed (simulate's default is "wall" whatever the scene says)
    traj = simulate(run_scene, every=1, wall_speed=run_scene.world.wall_speed)
    return run_scene, traj, time.perf_counter() - start


def _energies(scene, traj, frames) -> list[float]:
    """Total energy of each of ``frames`` of ``traj``, by the loop's own
    formula (:meth:`refsim.Simulation.energy` with the frame's state put in)."""
    sim = Simulation(scene)
    out = []
    for frame in frames:
        R = traj.orientation[frame]
        sim.R[...] = R
        sim.x[...] = traj.position[frame] + np.einsum("bij,bj->bi", R, sim.center)
        sim.v[...] = traj.velocity[frame]
        sim.w[...] = traj.angular_velocity[frame]
        out.append(float(sim.energy().sum()))
    return out


def _impacts(traj, radius: np.ndarray) -> list[tuple[tuple, float, float]]:
    """``(channel, time, response speed)`` of each event of ``traj`` (every
    step recorded); the speed from the frames around the step that found it."""
    index = {name: i for i, name in enumerate(traj.names)}
    dv = np.linalg.norm(np.diff(traj.velocity, axis=0), axis=2)          # (steps, B)
    dw = np.linalg.norm(np.diff(traj.angular_velocity, axis=0), axis=2)
    speed = dv + radius * dw
    out = []
    for e in traj.events:
        u = speed[e.step - 1]
        s = u[index[e.body]] if e.kind == "wall" else max(u[index[e.body]], u[index[e.other]])
        out.append(((e.kind, e.body, e.other), e.time, float(s)))
    return out


def _unmatched(ours, theirs, tolerance: float, horizon: float) -> str:
    for channel, t, speed in ours:
        if speed < CHECK_SPEED or t + tolerance / speed > horizon:
            continue
        if not any(c == channel and abs(s - t) * speed <= tolerance for c, s, _ in theirs):
            return f"{' '.join(channel)} at {t:.6g} s ({speed:.3g} m/s) has no twin"
    return ""


def check_advice(scene, advice) -> AdviceCheck:
    """Re-run the reference and the recommendation of ``advice`` (for
    ``scene``, a :class:`refsim.Scene`) and compare them (module docstring)."""
    ref, rec = advice.reference, advice.recommended
    tol, horizon, duration = advice.tolerance, ref.horizon, advice.duration
    ref_scene, ref_traj, ref_seconds = _trajectory(
        scene, Fidelity(ref.solver, ref.step, ref.level, ref.aabb), duration)
    rec_scene, rec_traj, rec_seconds = _trajectory(scene, rec.fidelity(), duration)
    # common times: frame i of the reference (step h_r) and j of the
    # recommendation (step h) at one time when i h_r = j h; with h_r = s/M and
    # h = s/m on the sample interval s, that is i m = j M
    M = round(advice.sample_interval / ref.step)
    m = round(advice.sample_interval / rec.step)
    g = gcd(M, m)
    n_common = (len(rec_traj.t) - 1) // (m // g) + 1
    i = np.arange(n_common) * (M // g)
    j = np.arange(n_common) * (m // g)
    keep = ref_traj.t[i] <= horizon + 1e-12
    radius = np.array([np.linalg.norm(ref_scene.mesh(b).scaled(b.scale).vertices, axis=1).max()
                       for b in ref_scene.bodies])
    d = ref_traj.position[i[keep]] - rec_traj.position[j[keep]]
    dR = ref_traj.orientation[i[keep]] - rec_traj.orientation[j[keep]]
    gap = (np.linalg.norm(d, axis=2)
           + radius * np.sqrt((dR * dR).sum(axis=(2, 3)) / 2.0)).max(axis=1)
    samples = (j[keep] % m) == 0                          # the advisor's sample times
    ours, theirs = _impacts(ref_traj, radius), _impacts(rec_traj, radius)
    note = (_unmatched(ours, theirs, tol, horizon)
            or _unmatched(theirs, ours, tol, horizon))
    # the energy scale: the reference's largest energy at the sample times
    ref_energy = _energies(ref_scene, ref_traj, [*range(0, len(ref_traj.t), M), -1])
    scale = max(ref_energy) if max(ref_energy) > 0.0 else 1.0
    energy_gap = (_energies(rec_scene, rec_traj, [-1])[0] - ref_energy[-1]) / scale
    position_steps = float(gap.max())
    position_samples = float(gap[samples].max())
    meets = (position_samples <= tol and not note
             and abs(energy_gap) <= advice.energy_allowance * (1.0 + 1e-9))
    return AdviceCheck(
        scene=advice.scene, tolerance=tol, horizon=horizon,
        recommended=rec.fidelity().label(), position_error_steps=position_steps,
        position_error_samples=position_samples, events_equal=not note,
        event_note=note, energy_gap=float(energy_gap), energy_allowance=advice.energy_allowance,
        meets=meets, reference_seconds=ref_seconds, recommended_seconds=rec_seconds)


def main(argv: list[str] | None = None) -> None:
    """Advise and check every bundled rigid-body scene at the tolerances given
    (a series per scene, as the report's advisor section)."""
    from refsim.advisor.advice import BUNDLED_RIGID_SCENES, advice_by_tolerance
    from refsim.scenes.loader import load_scene

    parser = argparse.ArgumentParser(prog="python -m refsim.advisor.check")
    parser.add_argument("scenes", nargs="*", default=list(BUNDLED_RIGID_SCENES))
    parser.add_argument("--tolerances", type=float, nargs="+", default=[1e-2, 1e-3])
    parser.add_argument("--workers", type=int)
    parser.add_argument("--store", help="a directory; one store per scene inside it")
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args(argv)
    backend = "processes" if args.workers else "inprocess"
    print("scene  TOL m  converged  horizon s  recommended  proxy  own proxy  saving  own meets"
          "  | check: pos err (samples, every step) m  events  energy gap  meets")
    for name in args.scenes:
        scene = load_scene(name)
        (series,) = advice_by_tolerance((name,), tuple(args.tolerances), store=args.store,
                                        backend=backend, workers=args.workers,
                                        repeats=args.repeats, progress=False)
        for tol, advice in zip(series.tolerances, series.advice, strict=True):
            check = check_advice(scene, advice)
            rec, own = advice.recommended, advice.own
            print(f"{name}  {tol:g}  {advice.reference.converged}  {advice.reference.horizon:g}"
                  f"  {check.recommended}  {rec.proxy}  {own.proxy}  "
                  f"{advice.proxy_saving:.3g}x  {own.meets}  |  "
                  f"{check.position_error_samples:.3g}, {check.position_error_steps:.3g}  "
                  f"{'equal' if check.events_equal else check.event_note}  "
                  f"{check.energy_gap:+.2g} (allowed {check.energy_allowance:.2g})  "
                  f"{check.meets}", flush=True)
            if not math.isfinite(check.position_error_steps):
                raise SystemExit(f"{name}: a check produced a non-finite error")


if __name__ == "__main__":
    main()
