"""Checks of the ``rigid`` capability on impacts with the floor: the bounces of
drops, symmetric and oblique landings, the energy of every scene with
contacts, determinism, and the times of the bounces.

The tolerances follow from what time-stepped contact allows
(:data:`~refsim.conformance.rigid_runs.CONTACT_STEPS`; the reasoning, and how a
miss is classified, are in :mod:`refsim.conformance.rigid_runs`).

- ``rigid.apex_ratio`` (drops of the sphere and the cube, e = 0.5 and 0.8,
  and of the icosahedron, e = 0.8):
  the apex ratio over K = 3 bounces is ``e^2`` within
  ``CONTACT_STEPS h sqrt(2 g / h_K) / K`` relative, ``h_K = e^(2K) h0`` the
  last apex (an error of ``2 v_K h`` in that apex's height, shared by the
  K ratios of the geometric mean): 1.7 % at e = 0.5, 0.41 % at e = 0.8.
- ``rigid.no_spin`` (the same drops, frictionless, each landing on a
  vertex, face or edge straight below the centre of mass): no contact
  impulse has a moment about the centre, so the body must not turn; its
  largest angular speed times its reach stays below
  :data:`NO_SPIN_FRACTION` of the impact speed.
- ``rigid.oblique_bounce`` (the sphere striking the floor obliquely, in
  every regime: sliding throughout, leaving rolling, spin only at e = 1,
  backspin that reverses the lateral velocity, e = 0): the lateral velocity
  and the spin after the impact are Coulomb's over the whole impact
  (:func:`refsim.dynamics.analytic.oblique_impact_ball`) within ``mu
  CONTACT_STEPS g h`` (friction spread over the steps of a contact meets
  gravity's ``g h`` per step) plus what a contact found ``CONTACT_STEPS``
  late costs a spinning mesh: it has turned by ``(t_fall + CONTACT_STEPS h)
  |w|`` (``t_fall``: the scene's fall to the floor, height over speed), its
  contact vertex is that far (times the radius) off the vertical and moves
  along the normal at ``|w|`` times that lever, which changes the normal
  impulse by ``m (1 + e) |w| lever`` and the friction by ``mu`` times that.
  The spin is allowed what that friction does to it (``radius m / I`` times
  the velocity's tolerance) plus the normal impulse ``m (1 + e) v_n`` acting
  on the lever.
  The velocity is read ``CONTACT_STEPS`` steps after the impact. One that
  matches the seed's law ``(1 - friction) v_t`` instead (S5, S7) is
  "known-divergence".
- ``rigid.energy`` (every scene with contacts; the free brick's energy is
  ``rigid.free_rotation``'s): the mechanical energy never exceeds its
  initial value by more than ``CONTACT_STEPS m g v_max h`` (a contact
  resolved a step late may leave the body ``2 v h`` higher), ``v_max`` the
  scene's largest speed.
- ``rigid.determinism`` (the oblique and the spinning scene): a second run
  of the same scene in the same engine gives the same trajectory, bit for bit.
- ``rigid.bounce_times`` (the drops of ``rigid.apex_ratio``): the first
  ``BOUNCES`` bounces happen at ``t1 = sqrt(2 H / g)``, ``t_{k+1} = t_k + 2
  e^k v1 / g`` (:func:`refsim.dynamics.analytic.bounce_times`), each read
  from the trajectory by fitting the free flight after it with the closed
  form's gravity and extrapolating it back to the floor
  (:func:`bounce_times`). RK4 is exact for a constant force, so an engine
  that integrates the flight with the scene's RK4 and places each impact at
  its time within the step meets the closed form to rounding; the fit is
  exact for such a flight. The tolerance is :data:`BOUNCE_TIME_STEPS` of a
  step: a time of impact interpolated linearly within the step stays
  inside it, a bounce resolved at the end of its step (up to a step late,
  accumulating over the bounces) or a semi-implicit Euler fall (it lands
  half a step early) does not.
"""

from __future__ import annotations

import math
import time

import numpy as np

from refsim.conformance import cases_rigid as R
from refsim.conformance.results import CheckResult, Crash, attempt, classify_miss, tally
from refsim.conformance.rigid_runs import CONTACT_STEPS, _flights, _law, _runs, energy_tolerance
from refsim.dynamics import analytic

#: A frictionless symmetric landing may leave the body turning only this
#: fast: its surface speed (|w| times its reach) a thousandth of the impact
#: speed, far above rounding (1e-12 and below in refsim and MuJoCo), far
#: below a spin that changes a bounce visibly.
NO_SPIN_FRACTION = 1e-3


def apex_tolerance(scene) -> float:
    """Relative apex-ratio tolerance of a drop (module docstring)."""
    h_K = scene.height * scene.e ** (2 * R.BOUNCES)
    h = scene.scene.integration.step
    return CONTACT_STEPS * h * math.sqrt(2.0 * R.GRAVITY / h_K) / R.BOUNCES


def check_rigid_apex_ratio(engine, cases) -> CheckResult:
    """``rigid.apex_ratio``: apex ratio e^2 in every drop (module docstring)."""
    start = time.perf_counter()
    outcomes: list[str | None] = []
    examples: list[dict] = []
    measured: dict = {}
    for scene, trajectory in _runs(engine, cases, ("drop",), outcomes, examples):
        ratio, heights = R.apex_ratio(scene, trajectory)
        ideal = analytic.apex_ratio(scene.e)
        error = (ratio - ideal) / ideal
        tol = apex_tolerance(scene)
        measured[scene.name] = {"ratio": ratio, "relative_error": error, "tolerance": tol}
        example = {"apex_ratio": ratio, "ideal": ideal, "relative_error": error,
                   "tolerance": tol, "apex_heights": heights,
                   "analytic_heights": analytic.apex_heights(scene.height, scene.e,
                                                             R.BOUNCES).tolist()}
        if math.isfinite(error):
            outcome = classify_miss(abs(error), tol)
        else:
            outcome = "unmeasurable"
            example["reason"] = (f"{max(len(heights) - 1, 0)} apexes after the release, "
                                 f"{R.BOUNCES} needed (the body bounced fewer times in "
                                 f"{float(trajectory.t[-1]):g} s)")
        outcome = _law(engine, outcome, example)
        outcomes.append(outcome)
        if outcome is not None:
            examples.append({"class": outcome, **example, **scene.to_dict()})
    return tally("rigid", "apex_ratio", outcomes, examples=examples, measured=measured,
                 seconds=time.perf_counter() - start)


def check_rigid_no_spin(engine, cases) -> CheckResult:
    """``rigid.no_spin``: a frictionless drop landing straight below the
    centre of mass does not start the body turning (module docstring)."""
    start = time.perf_counter()
    outcomes: list[str | None] = []
    examples: list[dict] = []
    measured: dict = {}
    for scene, trajectory in _runs(engine, cases, ("drop",), outcomes, examples):
        vertices, _, _ = R._body(R._model(scene))
        reach = float(np.sqrt((vertices ** 2).sum(axis=1)).max())
        spin = float(np.sqrt((np.asarray(trajectory.angular_velocity)[:, 0] ** 2)
                             .sum(axis=1)).max())
        impact = analytic.impact_speed(scene.height, R.GRAVITY)
        fraction = spin * reach / impact
        measured[scene.name] = {"largest_spin": spin, "surface_speed_fraction": fraction}
        outcome = classify_miss(fraction, NO_SPIN_FRACTION) if math.isfinite(fraction) else "bug"
        outcomes.append(outcome)
        if outcome is not None:
            examples.append({"class": outcome, "largest_spin": spin,
                             "surface_speed_over_impact_speed": fraction,
                             "limit": NO_SPIN_FRACTION, **scene.to_dict()})
    return tally("rigid", "no_spin", outcomes, examples=examples, measured=measured,
                 seconds=time.perf_counter() - start)


def _after_impact(trajectory, h: float) -> int:
    """The first frame at least ``CONTACT_STEPS`` steps of ``h`` (by the
    frames' times, however many frames the engine keeps) after the first
    impact, the first frame whose vertical velocity is above the previous
    frame's by more than the fall's ``g h`` per step can explain (the
    bounce)."""
    t = np.asarray(trajectory.t)
    v_y = np.asarray(trajectory.velocity)[:, 0, 1]
    jump = np.diff(v_y) - 2.0 * R.GRAVITY * np.diff(t)
    k = np.flatnonzero(jump > 0.0)
    if not len(k):
        return len(t) - 1
    later = np.flatnonzero(t >= t[int(k[0]) + 1] + (CONTACT_STEPS - 0.5) * h)
    return int(later[0]) if len(later) else len(t) - 1


def check_rigid_oblique_bounce(engine, cases) -> CheckResult:
    """``rigid.oblique_bounce``: Coulomb's lateral velocity and spin after an
    oblique impact, in every regime (module docstring)."""
    start = time.perf_counter()
    outcomes: list[str | None] = []
    examples: list[dict] = []
    measured: dict = {}
    for scene, trajectory in _runs(engine, cases, ("oblique",), outcomes, examples):
        k = _after_impact(trajectory, scene.scene.integration.step)
        body = scene.scene.bodies[0]
        v_n, coulomb, coulomb_spin = R.oblique_answer(scene)
        got = float(np.asarray(trajectory.velocity)[k, 0, 0])
        spin = float(np.asarray(trajectory.angular_velocity)[k, 0, 2])
        seed_law = analytic.lateral_velocity_seed(body.velocity[0], scene.friction)
        h = scene.scene.integration.step
        vertices, _, inertia = R._body(R._model(scene))
        radius = float(np.sqrt((vertices ** 2).sum(axis=1)).max())
        w_0 = abs(body.angular_velocity[2])
        I_zz = float(inertia[2, 2])                   # per unit mass
        # the contact vertex, turned off the vertical by the spin during the
        # fall to the floor and the steps before the contact is found, moves
        # along n at w_0 lever: that changes the normal impulse by (1 + e) w_0
        # lever (per unit mass), and so the friction by mu times that; the
        # normal impulse acts on the lever
        fall = scene.height / abs(body.velocity[1]) if body.velocity[1] else 0.0
        lever = (fall + CONTACT_STEPS * h) * w_0 * radius
        tol = scene.friction * (CONTACT_STEPS * R.GRAVITY * h
                                + (1.0 + scene.e) * w_0 * lever)
        spin_tol = tol * radius / I_zz + lever * (1.0 + scene.e) * v_n / I_zz
        error = max(abs(got - coulomb) / tol, abs(spin - coulomb_spin) / spin_tol)
        outcome = classify_miss(error, 1.0) if math.isfinite(error) else "bug"
        if outcome is not None and abs(got - seed_law) <= tol:
            outcome = "known-divergence"
        example = {"lateral_velocity": got, "coulomb": coulomb, "spin": spin,
                   "coulomb_spin": coulomb_spin, "seed_law": seed_law,
                   "impact_normal_speed": v_n, "tolerance": tol, "spin_tolerance": spin_tol}
        outcome = _law(engine, outcome, example)
        measured[scene.name] = {"lateral_velocity": got, "coulomb": coulomb,
                                "spin": spin, "coulomb_spin": coulomb_spin,
                                "seed_law": seed_law, "tolerance": tol,
                                "spin_tolerance": spin_tol}
        outcomes.append(outcome)
        if outcome is not None:
            examples.append({"class": outcome, **example, **scene.to_dict()})
    return tally("rigid", "oblique_bounce", outcomes, examples=examples, measured=measured,
                 seconds=time.perf_counter() - start)


def check_rigid_energy(engine, cases) -> CheckResult:
    """``rigid.energy``: with restitution <= 1 and no driving force the
    mechanical energy never rises beyond :func:`energy_tolerance`."""
    start = time.perf_counter()
    outcomes: list[str | None] = []
    examples: list[dict] = []
    measured: dict = {}
    for scene, trajectory in _runs(engine, cases, ("drop", "oblique", "spin", "rest"),
                                   outcomes, examples):
        energy = R.energy(scene, trajectory)
        rise = float((energy - energy[0]).max())
        tol = energy_tolerance(scene)
        measured[scene.name] = {"largest_rise": rise, "tolerance": tol,
                                "initial": float(energy[0])}
        outcome = classify_miss(rise, tol) if math.isfinite(rise) else "bug"
        outcomes.append(outcome)
        if outcome is not None:
            k = int(np.nanargmax(energy))
            examples.append({"class": outcome, "largest_rise": rise, "tolerance": tol,
                             "at_time": float(np.asarray(trajectory.t)[k]),
                             "initial_energy": float(energy[0]), **scene.to_dict()})
    return tally("rigid", "energy", outcomes, examples=examples, measured=measured,
                 seconds=time.perf_counter() - start)


def _same(a, b) -> bool:
    names = ("t", "position", "velocity", "angular_velocity", "orientation")
    return all(np.array_equal(np.asarray(getattr(a, n)), np.asarray(getattr(b, n)),
                              equal_nan=True) for n in names)


def check_rigid_determinism(engine, cases) -> CheckResult:
    """``rigid.determinism``: a second run gives the same frames, bit for bit."""
    start = time.perf_counter()
    outcomes: list[str | None] = []
    examples: list[dict] = []
    for scene, first in _runs(engine, cases, ("oblique", "spin"), outcomes, examples):
        second = attempt(cases.rerun, engine, scene)
        if isinstance(second, Crash):
            outcomes.append("crash")
            examples.append(second.example(run="the second", **scene.to_dict()))
            continue
        same = _same(first, second)
        outcomes.append(None if same else "bug")
        if not same:
            a, b = np.asarray(first.position), np.asarray(second.position)
            diff = float(np.nanmax(np.abs(a - b))) if a.shape == b.shape else math.inf
            examples.append({"class": "bug", "largest_position_difference": diff,
                             **scene.to_dict()})
    return tally("rigid", "determinism", outcomes, examples=examples,
                 seconds=time.perf_counter() - start)

#: The bounce times' tolerance, in steps (module docstring): far above what
#: an exact time of impact and RK4's exact parabola leave (rounding, 1e-12
#: s), above a time of impact found by interpolating the depth linearly
#: within the step (at most ``g h^2 / (8 v)`` a bounce: 2.3e-3 steps by the
#: third bounce at the slowest impact here, 1.57 m/s), and far below the
#: half step by which a semi-implicit Euler fall lands early or a bounce
#: found at the end of its step lands late.
BOUNCE_TIME_STEPS = 0.01

#: A flight shorter than this many frames is not read as a bounce's arc.
ARC_FRAMES = 5


def bounce_times(scene, trajectory) -> list[float]:
    """The times of the bounces (s), each read from the free flight after it
    (:func:`_flights`, after the fall): the lowest vertex's height over the
    flight's frames, fitted by least squares with ``y + g t^2 / 2 = a + b
    t`` (the closed form's gravity), extrapolated back to the floor (the
    earlier root of ``a + b t - g t^2 / 2``)."""
    t = np.asarray(trajectory.t)
    heights = R.lowest_height(scene, trajectory)
    times = []
    for first, last in _flights(trajectory):
        if first == 0 or last - first + 1 < ARC_FRAMES:
            continue                                  # the fall, or a contact's gap
        s = t[first:last + 1] - t[first]
        b, a = np.polyfit(s, heights[first:last + 1] + 0.5 * R.GRAVITY * s * s, 1)
        root = b * b + 2.0 * R.GRAVITY * a
        if not (math.isfinite(root) and root >= 0.0):
            times.append(math.nan)
            continue
        times.append(float(t[first] - 2.0 * a / (b + math.sqrt(root))))
    return times


def check_rigid_bounce_times(engine, cases) -> CheckResult:
    """``rigid.bounce_times``: the drops bounce at t1 = sqrt(2 H / g) and
    t_{k+1} = t_k + 2 e^k v1 / g (module docstring)."""
    start = time.perf_counter()
    outcomes: list[str | None] = []
    examples: list[dict] = []
    measured: dict = {}
    for scene, trajectory in _runs(engine, cases, ("drop",), outcomes, examples):
        closed = analytic.bounce_times(scene.height, R.GRAVITY, scene.e, R.BOUNCES)
        got = bounce_times(scene, trajectory)[:R.BOUNCES]
        h = scene.scene.integration.step
        tol = BOUNCE_TIME_STEPS * h
        misses = [g - c for g, c in zip(got, closed, strict=False)]
        worst = (max(abs(m) for m in misses) if len(got) == R.BOUNCES
                 and all(math.isfinite(m) for m in misses) else math.nan)
        measured[scene.name] = {"bounce_times": got, "closed_form": closed.tolist(),
                                "misses_in_steps": [m / h for m in misses],
                                "largest_miss": worst, "tolerance": tol}
        example = {"bounce_times": got, "closed_form": closed.tolist(),
                   "misses_in_steps": [m / h for m in misses], "tolerance": tol}
        outcome: str | None
        if len(got) < R.BOUNCES:
            outcome = "unmeasurable"
            example["reason"] = (f"{len(got)} flights after a bounce, {R.BOUNCES} needed "
                                 f"(the body bounced fewer times in {float(trajectory.t[-1]):g} s)")
        else:
            outcome = classify_miss(worst, tol) if math.isfinite(worst) else "bug"
        outcome = _law(engine, outcome, example)
        outcomes.append(outcome)
        if outcome is not None:
            examples.append({"class": outcome, **example, **scene.to_dict()})
    return tally("rigid", "bounce_times", outcomes, examples=examples, measured=measured,
                 seconds=time.perf_counter() - start)
