"""Checks of the ``rigid`` capability against analytic answers.

Every tolerance below follows from one fact about time-stepped contact: an
engine finds a contact only at a step, so a bounce can happen up to a step
late and be resolved over a step or two. With :data:`CONTACT_STEPS` = 2
steps of size ``h`` at impact speed ``v`` the bounce point can move by up to
``2 v h``, and a friction impulse spread over those steps can include
gravity's ``m g h`` per step. refsim's corrected model meets the answers to
rounding; first-order engines (Bullet, MuJoCo: semi-implicit Euler) must
meet them within these bounds.

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
- ``rigid.spin_to_rest`` (the cube spinning flat on the floor): by
  :func:`spin_rest_time` its angular speed is below
  :data:`SPIN_REST_FRACTION` of the initial one. Coulomb friction at the
  face brings it to rest in ``w0 I / (mu m g r)``, ``r`` the mean lever arm
  of the contact pressure: the face's corners, ``r = s / sqrt(2)``, for
  contact at the vertices; a uniform pressure over the face, ``r = 0.3826
  s``, is the slowest plausible distribution; the limit is twice that
  (0.89 s here).
- ``rigid.energy`` (every scene with contacts; the free brick's energy is
  ``rigid.free_rotation``'s): the mechanical energy never exceeds its
  initial value by more than ``CONTACT_STEPS m g v_max h`` (a contact
  resolved a step late may leave the body ``2 v h`` higher), ``v_max`` the
  scene's largest speed.
- ``rigid.resting_contact`` (the resting cube; the spinning cube after it
  should have stopped): the lowest vertex is never deeper than
  :data:`REST_PENETRATION_STEPS` ``g h^2`` below the floor (gravity moves a
  resting body ``g h^2`` into the floor per step before a contact acts; a
  soft-contact engine holds a steady penetration of that order).
- ``rigid.determinism`` (the oblique and the spinning scene): a second run
  of the same scene in the same engine gives the same trajectory, bit for bit.
- ``rigid.free_rotation`` (the free brick, spun near its middle axis):
  torque-free motion as Euler's equations give it in closed form
  (:class:`refsim.dynamics.free_body.FreeBody`; Landau & Lifshitz,
  *Mechanics*, section 37): the body-frame angular velocity about the middle
  axis changes sign as often as the closed form's in the same time, the
  mean time between the flips is the closed form's within
  :data:`FLIP_INTERVAL_TOL`, and the kinetic energy stays within
  :data:`FREE_ENERGY_TOL` of its start, and so does the world angular
  momentum (no contact, no force: any change is the integrator's). For an
  engine that declares its ``integrator_order`` p, a drift beyond that is
  measured again at h / 2: one that falls by 2^p (within
  :data:`DRIFT_ORDER_TOL` in the exponent) and stays within
  :data:`DRIFT_EXCUSE_LIMIT` is the integrator's truncation error,
  "tolerance" (over a fixed time a method of order p errs by O(h^p):
  Hairer, Norsett, Wanner, *Solving ODEs I*, II.3).

- ``rigid.off_centre`` (the ball striking the free rod 1.5 m off its centre,
  frictionless, e = 1 and 0.5): after the impact the rod's velocity and
  spin and the ball's velocity are the impulse solution
  (:func:`refsim.conformance.cases_rigid.strike_answer`), the rod does not
  slide sideways and the ball does not spin, each within
  :data:`OFF_CENTRE_TOL` of the closing speed (a spin as the speed it gives
  at its lever: the strike's offset for the rod, the radius for the ball);
  and the angular momentum about the world origin stays within
  :data:`MOMENTUM_TOL` of its start (no force but the contact's, whose
  impulses are equal and opposite at one point).
- ``rigid.incline`` (a block on an incline, sliding at 30 degrees with mu
  0.3, sticking at 10 degrees and at 50 degrees with mu 1.5): its travel
  down the slope in 1 s is Coulomb's
  (:func:`refsim.conformance.cases_rigid.incline_answer`) within
  :func:`incline_tolerance`: a first-order step's error ``a h t / 2`` in
  ``a t^2 / 2``, and friction that acts up to :data:`CONTACT_STEPS` steps
  late on each of the ``t / h`` steps of a resting contact, whose sliding
  speed gains ``g h`` per step before it acts: ``CONTACT_STEPS g h t``
  (about 2 cm at h = 1e-3, where a frictionless block would slide
  metres). A scene the engine cannot pose is not posed, with the key.
- ``rigid.stack`` (a cube resting 0.3 m off the centre of another; a rod
  overhanging a cube, its centre of mass over the cube; a cube on a rod
  lying on the floor, 1.5 m from the rod's centre): every vertex of every
  body stays within :data:`STACK_TRAVEL` of where it started (each body is
  statically stable: the answer is that nothing moves).
- ``rigid.cradle`` (Newton's cradle: three balls in a row at e = 1, two at
  e = 0.5, apart, frictionless, no gravity, the first at 1 m/s): after the
  pulse has crossed the row each ball's velocity along the row is the
  chain of binary impacts' (:func:`refsim.conformance.cases_rigid.cradle_answer`),
  its velocity across the row and its spin (as the speed at its radius)
  are 0, each within :data:`CRADLE_TOL` of the first ball's speed; the
  kinetic energy is the answer's within twice that (the energy of
  velocities within ``d`` of answers whose magnitudes sum to v is within
  ``2 d`` of it, relative), and the momentum never leaves its start by
  more than :data:`MOMENTUM_TOL` (equal and opposite impulses). The
  velocities are read at the end of the run (20 ms; the pulse crosses in
  5.4 ms); neighbours still closing then are recorded (an engine whose
  contact outlasts the run has not finished the impacts). A miss of
  an engine that declares a contact law other than restitution is "law":
  the answer is Newton's impact law's.

- ``rigid.slide_to_roll`` (the sphere and the cube set sliding on the floor at
  3 m/s without spin, mu 0.3, e = 0): by Coulomb's kinetic friction
  (:func:`refsim.conformance.cases_rigid.slide_answer`) the centre
  decelerates at ``mu g`` while the contact slips; the slip ends at ``v0 /
  (mu g (1 + d^2 / k^2))`` for the sphere (2 v0 / (7 mu g) for a smooth
  solid ball; here with the mesh's own ``k`` and contact depth ``d``), at
  ``v0 / (mu g)`` for the cube, which stops after ``v0^2 / (2 mu g)``.
  The deceleration is the least-squares slope of the centre's speed over
  the frames from ``CONTACT_STEPS h`` to :data:`SLIDE_WINDOW` of the closed
  form's slip time, within :func:`slide_tolerance` of ``mu g``: what the
  facets do to it (:func:`slide_facet_shift`: 0.85 % for the sphere-2k
  model over its window, 0 for the cube's face) plus ``2 CONTACT_STEPS h /
  T`` (friction up to ``CONTACT_STEPS`` steps late at either end of a
  window of ``T``, each moving the speed by ``CONTACT_STEPS mu g h``): 2.4
  % for the ball, 0.44 % for the cube at h = 1e-3. The slip ends (the
  first frame whose slip is below what ``CONTACT_STEPS`` steps of the
  closed form's slip rate take) within that fraction of the closed form's
  time plus ``CONTACT_STEPS h``; the cube's travel is within that fraction
  of ``v0^2 / (2 mu g)`` plus ``v0 CONTACT_STEPS h`` (friction found that
  late at the start). The ball's speed after the slip is recorded, not
  judged: the faceted ball rocks over a facet every 0.12 rad it turns and
  each landing takes about 1 % of its energy (measured in every engine:
  2.09 m/s 0.3 s after the slip where a smooth ball keeps 2.15), which the
  closed form of a smooth ball does not have.
- ``rigid.elastic_tumble`` (the brick dropped spinning, e = 1, no friction,
  5 s): exact impacts and an exact integrator keep the mechanical energy
  exactly (an impulse at one point with e = 1 and no friction returns the
  normal speed and so the kinetic energy: Stronge, *Impact Mechanics*, ch.
  2; between impacts only gravity does work). A step method finds each
  impact at a step and may leave the body up to ``CONTACT_STEPS v h`` off
  where it struck, which is the energy check's ``CONTACT_STEPS m g v_max h``
  (:func:`energy_tolerance`) per impact: the largest relative change of the
  energy over the run is held to that times the impacts read from the
  trajectory (runs of frames whose vertical velocity changes by more than
  gravity's, :data:`FLIGHT_TOL`; a contact over several steps once):
  :func:`tumble_tolerance`, 0.62 % of the energy per impact here.
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

A failure within twice its tolerance is "tolerance"; beyond, "bug" (unless
recognised as above). An engine that declares a contact law other than a
restitution coefficient (``contact_law``, :func:`refsim.engines.declarations`)
is not held to the answers that assume one: its misses of
``rigid.apex_ratio``, ``rigid.oblique_bounce``, ``rigid.cradle``,
``rigid.elastic_tumble`` and ``rigid.bounce_times`` are "law", naming it.
An apex ratio or bounce times that cannot be read (fewer bounces than they
need) are "unmeasurable", with the reason. A scene whose ``simulate`` raises, or
returns arrays of other shapes than the contract's, is that scene's
"crash" in every check that reads it.

References: the analytic answers of :mod:`refsim.dynamics.analytic`
(Mirtich 1996, ch. 3; Stronge, *Impact Mechanics*, 2000); the spin-down of
a flat face under Coulomb friction, e.g. K. L. Johnson, *Contact
Mechanics*, Cambridge 1985, section 7.4 (torsion of a contact), with the
mean distance of a square's points from its centre, ``s (sqrt 2 + ln(1 +
sqrt 2)) / 6``.

Cost: the runs of :mod:`refsim.conformance.cases_rigid` (shared between the
checks) plus two reruns for ``rigid.determinism``; ``rigid.bounce_times``
reads the drops' runs, and :func:`slide_facet_shift` turns the sphere mesh's
vertices (1,002) through 2,001 angles per slide scene.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from refsim.conformance import cases_rigid as R
from refsim.conformance.results import (
    CheckResult,
    Crash,
    attempt,
    classify_miss,
    not_applicable,
    tally,
)
from refsim.dynamics import analytic

#: Steps over which an engine may find and resolve one contact (module docstring).
CONTACT_STEPS = 2

#: The spinning cube counts as at rest below this fraction of its initial
#: angular speed (0.05 rad/s of 5): a hundredth of the motion is left, far
#: below what a reader of the trajectory would call spinning.
SPIN_REST_FRACTION = 0.01

#: The mean distance of a square's points from its centre, per unit side.
SQUARE_MEAN_RADIUS = (math.sqrt(2.0) + math.log(1.0 + math.sqrt(2.0))) / 6.0

#: The spin-down time limit is this many times the slowest plausible one.
SPIN_TIME_FACTOR = 2.0

#: A frictionless symmetric landing may leave the body turning only this
#: fast: its surface speed (|w| times its reach) a thousandth of the impact
#: speed, far above rounding (1e-12 and below in refsim and MuJoCo), far
#: below a spin that changes a bounce visibly.
NO_SPIN_FRACTION = 1e-3

#: Resting penetration allowed, in units of ``g h^2`` (one step's fall from rest).
REST_PENETRATION_STEPS = 10

#: The free brick's mean time between flips, relative to the closed form's:
#: 1 % shifts the fifth flip by 5 % of an interval, about the width of the
#: flip itself; a second-order rotation step is at 1e-6 at h = 1e-3.
FLIP_INTERVAL_TOL = 0.01

#: The free brick's kinetic energy and world angular momentum may change by
#: this fraction of their start. Both are constants of the motion; a
#: second-order rotation step errs by O((h |w|)^2) = 1e-4 relative here
#: (h |w| = 0.01; refsim's splitting keeps the energy to 5e-7 and the
#: momentum to rounding), a first-order one by O(h |w|) = 1e-2 at every flip,
#: when W changes fastest. 1e-3 lies between the two. (The flip interval alone
#: does not catch a uniform scaling of W, which keeps the orbit's shape.)
FREE_ENERGY_TOL = 1e-3

#: The strike's velocities, as a fraction of the closing speed (2 m/s): the
#: impulse solution holds for an impact at one instant; an engine that
#: spreads it over a few steps (soft contact) lets the rod turn meanwhile and
#: its contact point move, by ``h |w| d`` per step (1.2e-3 of the lever here).
#: 2 % allows some fifteen such steps and shows a lever wrong by more than 2 %.
OFF_CENTRE_TOL = 0.02

#: The strike's angular momentum about the world origin, relative to its
#: start (|L| = 3 kg m^2/s): conserved by any impulse pair at one point, so
#: only rounding and an engine's own integration of the free motion change
#: it; 1e-3 is far above the first and far below a lever arm gone wrong
#: (10 cm of lever wrong is 3.6 % of it at e = 1).
MOMENTUM_TOL = 1e-3

#: How far a vertex of a resting stack may travel in its half second (m):
#: 1 mm in 2 s is creep a reader would see in a long run, at the same rate.
#: Resting contact settles within ``g h^2`` = 1e-5 m per step; a stable
#: solver stays within a few times that (pybullet's settling moves the
#: stacks 5e-5 to 1e-4 m in this half second).
STACK_TRAVEL = 2.5e-4

#: The cradle's velocities, as a fraction of the first ball's speed (1 m/s).
#: The closed form holds for impulses along the line of centres; the balls
#: meet pole to pole on the row's line, about which the sphere mesh's poles
#: are mirror-symmetric (the nearest vertices 7 degrees off, in pairs), so
#: the contact normal lies on the line by symmetry and no facet tilts it;
#: without gravity or friction a contact found a step late (0.3 mm deep)
#: changes no velocity. An impulse solver meets the answer to rounding
#: (refsim corrected and Bullet: 4e-16 of the speed). 1 % shows a normal tilted
#: by 0.6 degrees (the nearest facets' 7 degrees would show 12 %) or an
#: effective restitution off by 0.02, and is far above rounding.
CRADLE_TOL = 0.01


def _runs(engine, cases, kinds, outcomes: list, examples: list,
          not_posed: dict | None = None):
    """Each scene of ``kinds`` with the engine's trajectory of it; a scene
    whose run crashed is recorded in ``outcomes`` and ``examples`` (class
    "crash", the scene and the traceback's last line) and skipped. With
    ``not_posed``, a scene the engine refused as unposable
    (:class:`refsim.errors.UnposableKey`) goes there instead, by name, with
    the refusal's line."""
    for scene in cases.of_kind(*kinds):
        trajectory = attempt(cases.run, engine, scene)
        if not_posed is not None and isinstance(trajectory, Crash) and trajectory.unposable:
            not_posed[scene.name] = trajectory.error.split(":", 1)[1].strip()
            continue
        if isinstance(trajectory, Crash):
            outcomes.append("crash")
            examples.append(trajectory.example(**scene.to_dict()))
            continue
        yield scene, trajectory


def _law(engine, outcome: str | None, example: dict) -> str | None:
    """``outcome``, or "law" for a miss of an engine that declares a contact
    law other than restitution (its name added to ``example``)."""
    from refsim.engines import RESTITUTION, declarations

    law = declarations(engine).contact_law
    if outcome is None or law == RESTITUTION:
        return outcome
    example["contact_law"] = law
    return "law"


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


def spin_rest_time(scene) -> float:
    """The time by which the spinning cube must be at rest (module docstring):
    ``SPIN_TIME_FACTOR w0 I_yy / (mu m g r)`` with ``r`` the uniform face
    pressure's mean lever arm."""
    vertices, _, inertia = R._body(R._model(scene))
    side = float(vertices[:, 0].max() - vertices[:, 0].min())
    body = scene.scene.bodies[0]
    w0 = float(np.abs(body.angular_velocity).max())
    # torque mu m g r over inertia I_yy m: the mass cancels
    deceleration = scene.friction * R.GRAVITY * SQUARE_MEAN_RADIUS * side / inertia[1, 1]
    return float(SPIN_TIME_FACTOR * w0 / deceleration)


def check_rigid_spin_to_rest(engine, cases) -> CheckResult:
    """``rigid.spin_to_rest``: the spinning cube is at rest by
    :func:`spin_rest_time` (module docstring)."""
    start = time.perf_counter()
    outcomes: list[str | None] = []
    examples: list[dict] = []
    measured: dict = {}
    for scene, trajectory in _runs(engine, cases, ("spin",), outcomes, examples):
        t = np.asarray(trajectory.t)
        speed = np.sqrt((np.asarray(trajectory.angular_velocity)[:, 0] ** 2).sum(axis=1))
        w0 = float(np.abs(scene.scene.bodies[0].angular_velocity).max())
        limit = spin_rest_time(scene)
        late = speed[t >= limit]
        left = float(late.max()) / w0 if len(late) else math.inf
        below = np.flatnonzero(speed < SPIN_REST_FRACTION * w0)
        measured[scene.name] = {"rest_time_limit": limit,
                                "first_time_below": float(t[below[0]]) if len(below) else None,
                                "largest_spin_after_limit": left * w0}
        outcome = classify_miss(left, SPIN_REST_FRACTION)
        outcomes.append(outcome)
        if outcome is not None:
            examples.append({"class": outcome, "rest_time_limit": limit,
                             "spin_after_limit": left * w0, "initial_spin": w0,
                             "final_angular_velocity":
                                 np.asarray(trajectory.angular_velocity)[-1, 0].tolist(),
                             **scene.to_dict()})
    return tally("rigid", "spin_to_rest", outcomes, examples=examples, measured=measured,
                 seconds=time.perf_counter() - start)


def _max_speed(scene) -> float:
    body = scene.scene.bodies[0]
    vertices, _, _ = R._body(R._model(scene))
    reach = float(np.sqrt((vertices ** 2).sum(axis=1)).max())
    fall = math.sqrt(float(np.dot(body.velocity, body.velocity))
                     + 2.0 * R.GRAVITY * max(scene.height, 0.0))
    spin = float(np.sqrt(np.dot(body.angular_velocity, body.angular_velocity))) * reach
    return max(fall + spin, R.GRAVITY * scene.scene.integration.step)


def energy_tolerance(scene) -> float:
    """Joules the energy may rise by in ``scene`` (module docstring)."""
    mass = scene.scene.bodies[0].mass
    return CONTACT_STEPS * mass * R.GRAVITY * _max_speed(scene) * scene.scene.integration.step


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


def check_rigid_resting_contact(engine, cases) -> CheckResult:
    """``rigid.resting_contact``: a body resting on the floor stays above it
    within ``REST_PENETRATION_STEPS g h^2`` (the spinning cube from its
    rest-time limit on)."""
    start = time.perf_counter()
    outcomes: list[str | None] = []
    examples: list[dict] = []
    measured: dict = {}
    for scene, trajectory in _runs(engine, cases, ("rest", "spin"), outcomes, examples):
        t = np.asarray(trajectory.t)
        heights = R.lowest_height(scene, trajectory)
        since = spin_rest_time(scene) if scene.kind == "spin" else 0.0
        depth = float(max(0.0, -heights[t >= since].min()))
        h = scene.scene.integration.step
        tol = REST_PENETRATION_STEPS * R.GRAVITY * h * h
        measured[scene.name] = {"deepest": depth, "tolerance": tol, "from_time": since}
        outcome = classify_miss(depth, tol)
        outcomes.append(outcome)
        if outcome is not None:
            examples.append({"class": outcome, "deepest_penetration": depth, "tolerance": tol,
                             "from_time": since, **scene.to_dict()})
    return tally("rigid", "resting_contact", outcomes, examples=examples, measured=measured,
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


#: How far the observed order of a free body's drift may be from the
#: engine's declared ``integrator_order`` for the drift to count as its
#: truncation error (the ODE order check's tolerance).
DRIFT_ORDER_TOL = 0.3

#: The largest drift a declared order excuses: twice what the shipped
#: first-order engines show at the kit's step (5.5 % over the brick's 12 s
#: at h = 1e-3), rounded up. Beyond it a run no longer approximates the
#: motion, whatever the order at which its error falls: "bug".
DRIFT_EXCUSE_LIMIT = 0.1


def _free_drifts(scene, trajectory) -> tuple[float, float]:
    """The free brick's largest relative energy drift and angular-momentum
    drift (world frame) over the run."""
    closed = R.free_body(scene)
    W = R.body_angular_velocity(trajectory)
    moments = np.array(closed.moments)
    energy = 0.5 * (W * W * moments).sum(axis=1)
    L = np.einsum("fij,fj->fi", np.asarray(trajectory.orientation)[:, 0], W * moments)
    momentum = float(np.sqrt(((L - L[0]) ** 2).sum(axis=1)).max()
                     / math.sqrt(closed.momentum_squared))
    return float(np.abs(energy / closed.energy - 1.0).max()), momentum


def _truncation_order(engine, cases, scene, drift: float) -> dict:
    """For an engine that declares ``integrator_order``: the scene run again
    at half the step, and the order at which the drift falls
    (``log2(drift / drift_half)``), as example fields;
    ``falls_at_declared_order`` when it is within DRIFT_ORDER_TOL of the
    declaration. ``{}`` for an engine that declares none."""
    from refsim.conformance.cases_rigid import with_step
    from refsim.engines import declarations

    order = declarations(engine).integrator_order
    if order is None:
        return {}
    half = with_step(scene, scene.scene.integration.step / 2.0)
    trajectory = attempt(cases.rerun, engine, half)      # not kept: the name is the same
    if isinstance(trajectory, Crash):
        return {"integrator_order": order, "half_step_run": trajectory.error}
    drift_half = max(_free_drifts(half, trajectory))
    observed = math.log2(drift / drift_half) if drift_half > 0.0 else math.inf
    return {"integrator_order": order, "drift_at_half_step": drift_half,
            "observed_drift_order": observed,
            "falls_at_declared_order": bool(abs(observed - order) <= DRIFT_ORDER_TOL),
            "excusable_drift_limit": DRIFT_EXCUSE_LIMIT}


def check_rigid_free_rotation(engine, cases) -> CheckResult:
    """``rigid.free_rotation``: the free brick flips as Euler's equations say,
    and keeps its energy (module docstring)."""
    start = time.perf_counter()
    outcomes: list[str | None] = []
    examples: list[dict] = []
    measured: dict = {}
    for scene, trajectory in _runs(engine, cases, ("free",), outcomes, examples):
        t = np.asarray(trajectory.t)
        closed = R.free_body(scene)
        W = R.body_angular_velocity(trajectory)
        flips = R.sign_changes(t, W[:, 1])
        expected = closed.flips(float(t[-1]))
        interval = float(np.diff(flips).mean()) if len(flips) > 1 else math.nan
        interval_error = abs(interval / closed.flip_interval - 1.0)
        energy_drift, momentum_drift = _free_drifts(scene, trajectory)
        drift = max(energy_drift, momentum_drift)
        measured[scene.name] = {"flips": len(flips), "closed_form_flips": expected,
                                "flip_interval": interval,
                                "closed_form_interval": closed.flip_interval,
                                "interval_error": interval_error,
                                "energy_drift": energy_drift, "momentum_drift": momentum_drift}
        drift_class = classify_miss(drift, FREE_ENERGY_TOL) if math.isfinite(drift) else "bug"
        truncation = {}
        if drift_class == "bug":
            truncation = _truncation_order(engine, cases, scene, drift)
            if truncation.get("falls_at_declared_order") and drift <= DRIFT_EXCUSE_LIMIT:
                drift_class = "tolerance"
            measured[scene.name].update(truncation)
        misses = [drift_class,
                  classify_miss(interval_error, FLIP_INTERVAL_TOL)
                  if math.isfinite(interval_error) else "bug",
                  None if len(flips) == expected else "bug"]
        outcome = "bug" if "bug" in misses else next((m for m in misses if m), None)
        outcomes.append(outcome)
        if outcome is not None:
            examples.append({"class": outcome, "flips": len(flips),
                             "closed_form_flips": expected, "flip_interval": interval,
                             "closed_form_interval": closed.flip_interval,
                             "energy_or_momentum_drift": drift,
                             "drift_tolerance": FREE_ENERGY_TOL, **truncation,
                             "interval_tolerance": FLIP_INTERVAL_TOL, **scene.to_dict()})
    return tally("rigid", "free_rotation", outcomes, examples=examples, measured=measured,
                 seconds=time.perf_counter() - start)


def check_rigid_off_centre(engine, cases) -> CheckResult:
    """``rigid.off_centre``: the strike's impulse solution and its angular
    momentum (module docstring)."""
    start = time.perf_counter()
    outcomes: list[str | None] = []
    examples: list[dict] = []
    measured: dict = {}
    for scene, trajectory in _runs(engine, cases, ("strike",), outcomes, examples):
        answer = R.strike_answer(scene)
        v = np.asarray(trajectory.velocity)[-1]
        w = np.asarray(trajectory.angular_velocity)[-1]
        got = {"rod_velocity": float(v[0, 1]), "rod_spin": float(w[0, 2]),
               "ball_velocity": float(v[1, 1]), "ball_spin": float(np.sqrt((w[1] ** 2).sum())),
               "rod_sideways_speed": float(math.hypot(v[0, 0], v[0, 2]))}
        # each miss as a speed: spins times their lever
        lever = {"rod_velocity": 1.0, "rod_spin": R.STRIKE_OFFSET, "ball_velocity": 1.0}
        misses = {k: abs(got[k] - answer[k]) * lever[k] for k in answer}
        misses["rod_sideways"] = got["rod_sideways_speed"]       # the answer is 0
        misses["ball_spin"] = got["ball_spin"] * R.BALL_SCALE     # frictionless: 0
        L = R.angular_momentum(scene, trajectory)
        drift = float(np.sqrt(((L - L[0]) ** 2).sum(axis=1)).max()
                      / np.sqrt((L[0] ** 2).sum()))
        worst = max(misses.values()) / R.STRIKE_SPEED
        measured[scene.name] = {**{f"{k}_answer": answer[k] for k in answer}, **got,
                                "largest_miss_of_closing_speed": worst,
                                "momentum_drift": drift}
        parts = [classify_miss(worst, OFF_CENTRE_TOL), classify_miss(drift, MOMENTUM_TOL)]
        outcome = ("bug" if "bug" in parts else next((p for p in parts if p), None))
        outcomes.append(outcome)
        if outcome is not None:
            examples.append({"class": outcome, **got,
                             **{f"{k}_answer": answer[k] for k in answer},
                             "misses_m_per_s": misses, "tolerance_of_closing_speed":
                             OFF_CENTRE_TOL, "momentum_drift": drift,
                             "momentum_tolerance": MOMENTUM_TOL, **scene.to_dict()})
    return tally("rigid", "off_centre", outcomes, examples=examples, measured=measured,
                 seconds=time.perf_counter() - start)


def check_rigid_stack(engine, cases) -> CheckResult:
    """``rigid.stack``: statically stable stacks stay (module docstring)."""
    start = time.perf_counter()
    outcomes: list[str | None] = []
    examples: list[dict] = []
    measured: dict = {}
    for scene, trajectory in _runs(engine, cases, ("stack",), outcomes, examples):
        travel = R.largest_vertex_travel(scene, trajectory)
        measured[scene.name] = {"largest_vertex_travel_metres": travel,
                                "tolerance_metres": STACK_TRAVEL}
        outcome = classify_miss(travel, STACK_TRAVEL) if math.isfinite(travel) else "bug"
        outcomes.append(outcome)
        if outcome is not None:
            examples.append({"class": outcome, "largest_vertex_travel_metres": travel,
                             "tolerance_metres": STACK_TRAVEL, **scene.to_dict()})
    return tally("rigid", "stack", outcomes, examples=examples, measured=measured,
                 seconds=time.perf_counter() - start)


def _cradle_energy(scene, trajectory, frame: int) -> float:
    """Kinetic energy (J) of the cradle's balls at ``frame``, translation and
    rotation, with the uniform solids' inertia (scaled)."""
    total = 0.0
    for i, body in enumerate(scene.scene.bodies):
        _, _, inertia = R._body(body.model.name)
        R_ = np.asarray(trajectory.orientation)[frame, i]
        v = np.asarray(trajectory.velocity)[frame, i]
        w = R_.T @ np.asarray(trajectory.angular_velocity)[frame, i]
        total += 0.5 * body.mass * (float(v @ v)
                                    + body.scale ** 2 * float(w @ (inertia @ w)))
    return total


def check_rigid_cradle(engine, cases) -> CheckResult:
    """``rigid.cradle``: Newton's cradle hands the first ball's velocity
    down the row by binary impacts (module docstring)."""
    start = time.perf_counter()
    outcomes: list[str | None] = []
    examples: list[dict] = []
    measured: dict = {}
    for scene, trajectory in _runs(engine, cases, ("cradle",), outcomes, examples):
        answer = R.cradle_answer(scene)
        bodies = scene.scene.bodies
        v = np.asarray(trajectory.velocity)[-1]
        w = np.asarray(trajectory.angular_velocity)[-1]
        speed = R.CRADLE_SPEED
        along = [float(v[i, 0]) for i in range(len(bodies))]
        across = [float(math.hypot(v[i, 1], v[i, 2])) for i in range(len(bodies))]
        spin = [float(np.sqrt((w[i] ** 2).sum())) for i in range(len(bodies))]
        misses = [max(abs(along[i] - answer[i]), across[i], spin[i] * b.scale) / speed
                  for i, b in enumerate(bodies)]
        # a nan velocity is a miss (max() would skip it by its place)
        worst = max(misses) if all(math.isfinite(m) for m in misses) else math.inf
        p = (np.asarray(trajectory.velocity)
             * np.array([b.mass for b in bodies])[None, :, None]).sum(axis=1)
        p0 = np.array([speed * bodies[0].mass, 0.0, 0.0])
        momentum_drift = float(np.sqrt(((p - p0) ** 2).sum(axis=1)).max()
                               / (speed * bodies[0].mass))
        e0 = 0.5 * bodies[0].mass * speed ** 2
        e_answer = sum(0.5 * b.mass * a * a for b, a in zip(bodies, answer, strict=True))
        energy = _cradle_energy(scene, trajectory, -1)
        energy_error = abs(energy - e_answer) / e0
        # neighbours still closing at the end: the impacts had not ended
        closing = [i + 1 for i in range(len(bodies) - 1)
                   if along[i] - along[i + 1] > CRADLE_TOL * speed]
        got = {"velocities_along": along, "speeds_across": across, "spins": spin,
               "answer_along": answer, "largest_miss_of_speed": worst,
               "still_closing_after_ball": closing,
               "kinetic_energy": energy, "kinetic_energy_answer": e_answer,
               "energy_error": energy_error, "momentum_drift": momentum_drift}
        measured[scene.name] = {**got, "tolerance_of_speed": CRADLE_TOL}
        parts = [classify_miss(worst, CRADLE_TOL) if math.isfinite(worst) else "bug",
                 classify_miss(energy_error, 2.0 * CRADLE_TOL)
                 if math.isfinite(energy_error) else "bug",
                 classify_miss(momentum_drift, MOMENTUM_TOL)
                 if math.isfinite(momentum_drift) else "bug"]
        outcome = "bug" if "bug" in parts else next((q for q in parts if q), None)
        example = {**got, "tolerance_of_speed": CRADLE_TOL,
                   "energy_tolerance": 2.0 * CRADLE_TOL, "momentum_tolerance": MOMENTUM_TOL}
        outcome = _law(engine, outcome, example)
        outcomes.append(outcome)
        if outcome is not None:
            examples.append({"class": outcome, **example, **scene.to_dict()})
    return tally("rigid", "cradle", outcomes, examples=examples, measured=measured,
                 seconds=time.perf_counter() - start)


def incline_tolerance(scene) -> float:
    """Metres of travel an incline scene allows (module docstring)."""
    a = math.radians(scene.angle)
    along = abs(R.GRAVITY * (math.sin(a) - scene.friction * math.cos(a)))
    h = scene.scene.integration.step
    t = scene.scene.integration.duration
    return (0.5 * along + CONTACT_STEPS * R.GRAVITY) * h * t


def check_rigid_incline(engine, cases) -> CheckResult:
    """``rigid.incline``: a block slides down an incline at Coulomb's
    acceleration, or sticks below its friction angle (module docstring)."""
    start = time.perf_counter()
    outcomes: list[str | None] = []
    examples: list[dict] = []
    measured: dict = {}
    not_posed: dict = {}
    for scene, trajectory in _runs(engine, cases, ("incline",), outcomes, examples,
                                   not_posed):
        travel = float(trajectory.position[-1, 0, 0] - trajectory.position[0, 0, 0])
        answer = R.incline_answer(scene)
        tol = incline_tolerance(scene)
        miss = abs(travel - answer)
        measured[scene.name] = {"travel_metres": travel, "coulomb_metres": answer,
                                "miss_metres": miss, "tolerance_metres": tol}
        outcome = classify_miss(miss, tol) if math.isfinite(miss) else "bug"
        outcomes.append(outcome)
        if outcome is not None:
            examples.append({"class": outcome, "travel_metres": travel,
                             "coulomb_metres": answer, "tolerance_metres": tol,
                             **scene.to_dict()})
    if not_posed and not outcomes:
        return not_applicable("rigid", "incline", "cannot pose: " + next(iter(
            not_posed.values())))
    if not_posed:
        measured["not_posed"] = not_posed
    return tally("rigid", "incline", outcomes, examples=examples, measured=measured,
                 seconds=time.perf_counter() - start)



# -- sliding, elastic tumbling, bounce times ------------------------------------------


#: The slide's deceleration is fitted over the frames from CONTACT_STEPS
#: steps after the start (friction may act that late) to this fraction of
#: the closed-form slip time: near its end a facet landing of the ball can
#: stop the slip early (its friction impulse, ``mu (1 + e)`` times the
#: landing's vertical speed of at most 0.12 m/s, times ``1 + d^2 / k^2`` on
#: the slip, is up to 0.13 m/s; a tenth of the slip is 0.3 m/s).
SLIDE_WINDOW = 0.9


def _slide_spin_up(scene, t: np.ndarray) -> np.ndarray:
    """The angle (rad, about z) the slide's body has turned at times ``t``
    by the closed form: the sphere spins up at ``mu g d / k^2`` (negative
    about z for a slide along +x); the cube does not turn."""
    if R._model(scene) != R.SPHERE:
        return np.zeros_like(t)
    _, _, inertia = R._body(R._model(scene))
    depth = R.slide_answer(scene)["depth"]
    return -0.5 * scene.friction * R.GRAVITY * depth / float(inertia[2, 2]) * t * t


def slide_facet_shift(scene, start: float, stop: float) -> float:
    """How far, relative to ``mu g``, the facets of the slide's mesh move the
    deceleration fitted over ``[start, stop]`` (module docstring).

    A smooth ball's centre stays at one height; the faceted one's rests on
    its lowest vertex, so as it turns its centre rises and falls (by 1.9 mm
    for the sphere-2k model) at ``dy/dt`` up to 0.12 m/s. The floor's
    normal force is ``m (g + d^2y/dt^2)``, and Coulomb's friction ``mu``
    times it, so the centre's speed along the floor is ``v0 - mu g t - mu
    (dy/dt - dy/dt(0))``: this returns the least-squares slope of the last
    term over the window, over ``mu g``, with the height read from the
    mesh's vertices turned by :func:`_slide_spin_up` (the body kept on the
    floor). Geometry only: no dynamics of any engine."""
    vertices, center, _ = R._body(R._model(scene))
    local = vertices - center
    t = np.linspace(start, stop, 2001)
    angle = _slide_spin_up(scene, t)
    height = -(np.sin(angle)[:, None] * local[None, :, 0]
               + np.cos(angle)[:, None] * local[None, :, 1]).min(axis=1)
    rise = np.gradient(height, t)
    slope = np.polyfit(t, -(rise - rise[0]), 1)[0]        # per mu
    return float(abs(slope) / R.GRAVITY)


def slide_window(scene) -> tuple[float, float]:
    """The fit window (s) of the slide's deceleration."""
    h = scene.scene.integration.step
    return CONTACT_STEPS * h, SLIDE_WINDOW * R.slide_answer(scene)["slip_end_time"]


def slide_tolerance(scene) -> float:
    """The slide's deceleration tolerance, relative to ``mu g`` (module
    docstring): the facets' share (:func:`slide_facet_shift`) plus ``2
    CONTACT_STEPS h / T`` over a window of ``T``."""
    start, stop = slide_window(scene)
    h = scene.scene.integration.step
    return slide_facet_shift(scene, start, stop) + 2.0 * CONTACT_STEPS * h / (stop - start)


def check_rigid_slide_to_roll(engine, cases) -> CheckResult:
    """``rigid.slide_to_roll``: a body set sliding on the floor decelerates
    at mu g until its contact stops slipping, at the closed form's time: a
    ball then rolls, a cube stops after v0^2 / (2 mu g) (module docstring)."""
    start = time.perf_counter()
    outcomes: list[str | None] = []
    examples: list[dict] = []
    measured: dict = {}
    for scene, trajectory in _runs(engine, cases, ("slide",), outcomes, examples):
        answer = R.slide_answer(scene)
        h = scene.scene.integration.step
        t = np.asarray(trajectory.t)
        v = np.asarray(trajectory.velocity)[:, 0]
        w = np.asarray(trajectory.angular_velocity)[:, 0]
        slip = v[:, 0] + w[:, 2] * answer["depth"]
        a, b = slide_window(scene)
        window = (t >= a) & (t <= b)
        ratio = math.nan
        if window.sum() >= 3 and np.isfinite(v[window, 0]).all():
            ratio = float(-np.polyfit(t[window], v[window, 0], 1)[0] / answer["deceleration"])
        tol = slide_tolerance(scene)
        v0 = float(scene.scene.bodies[0].velocity[0])
        t_star = answer["slip_end_time"]
        # the slip has ended once it is below what CONTACT_STEPS steps of
        # the closed form's slip rate take
        stopped = np.flatnonzero(slip <= CONTACT_STEPS * h * v0 / t_star)
        t_end = float(t[stopped[0]]) if len(stopped) else math.nan
        time_tol = t_star * tol + CONTACT_STEPS * h
        got = {"deceleration_over_mu_g": ratio, "deceleration_tolerance": tol,
               "slip_end_time": t_end, "closed_form_slip_end_time": t_star,
               "slip_end_tolerance": time_tol,
               "speed_at_slip_end": float(v[stopped[0], 0]) if len(stopped) else math.nan,
               "closed_form_speed_after": answer["speed_after"],
               "speed_at_end_of_run": float(v[-1, 0])}
        parts = [classify_miss(abs(ratio - 1.0), tol) if math.isfinite(ratio) else "bug",
                 classify_miss(abs(t_end - t_star), time_tol) if math.isfinite(t_end)
                 else "bug"]
        if "distance" in answer:
            x = np.asarray(trajectory.position)[:, 0, 0]
            travel = float(x[-1] - x[0])
            distance_tol = answer["distance"] * tol + v0 * CONTACT_STEPS * h
            got.update({"distance": travel, "closed_form_distance": answer["distance"],
                        "distance_tolerance": distance_tol})
            parts.append(classify_miss(abs(travel - answer["distance"]), distance_tol)
                         if math.isfinite(travel) else "bug")
        measured[scene.name] = got
        outcome = "bug" if "bug" in parts else next((p for p in parts if p), None)
        outcomes.append(outcome)
        if outcome is not None:
            examples.append({"class": outcome, **got, **scene.to_dict()})
    return tally("rigid", "slide_to_roll", outcomes, examples=examples, measured=measured,
                 seconds=time.perf_counter() - start)


#: A frame-to-frame change of the centre's vertical velocity within this
#: fraction of gravity's ``g dt`` is free flight (a contact in the step
#: changes it by its share of the body's weight at least, ``g dt`` for a
#: resting contact; rounding in RK4 or Euler is below 1e-12 of it).
FLIGHT_TOL = 1e-3


def _flights(trajectory) -> list[tuple[int, int]]:
    """The free flights of body 0: ``(first, last)`` frames of each run of
    frames between which the vertical velocity changes by gravity alone
    (:data:`FLIGHT_TOL`), in order."""
    t = np.asarray(trajectory.t)
    dv = np.diff(np.asarray(trajectory.velocity)[:, 0, 1])
    dt = np.diff(t)
    free = np.abs(dv + R.GRAVITY * dt) <= FLIGHT_TOL * R.GRAVITY * dt
    flights = []
    i = 0
    while i < len(free):
        if free[i]:
            j = i
            while j + 1 < len(free) and free[j + 1]:
                j += 1
            flights.append((i, j + 1))
            i = j + 1
        else:
            i += 1
    return flights


def _contacts(trajectory) -> int:
    """How many times body 0 met a wall: the runs of frames that are not
    free flight (:func:`_flights`), a contact over several steps once."""
    frames = len(np.asarray(trajectory.t))
    flights = _flights(trajectory)
    gaps = sum(1 for (_, last), (first, _) in zip(flights[:-1], flights[1:], strict=True)
               if first > last)
    ends = (flights[0][0] > 0) + (flights[-1][1] < frames - 1) if flights else 1
    return gaps + int(ends)


def tumble_tolerance(scene, contacts: int) -> float:
    """Relative energy change the elastic tumble allows after ``contacts``
    impacts (module docstring): :func:`energy_tolerance` for each, over the
    energy at the start."""
    body = scene.scene.bodies[0]
    _, center, inertia = R._body(R._model(scene))
    w = np.asarray(body.angular_velocity)
    start = (body.mass * R.GRAVITY * (body.position[1] + center[1] + R.HALF_SIZE)
             + 0.5 * body.mass * float(w @ inertia @ w)
             + 0.5 * body.mass * float(np.dot(body.velocity, body.velocity)))
    return max(contacts, 1) * energy_tolerance(scene) / start


def check_rigid_elastic_tumble(engine, cases) -> CheckResult:
    """``rigid.elastic_tumble``: a brick tumbling in the world cube with
    e = 1 and no friction keeps its mechanical energy (module docstring)."""
    start = time.perf_counter()
    outcomes: list[str | None] = []
    examples: list[dict] = []
    measured: dict = {}
    for scene, trajectory in _runs(engine, cases, ("tumble",), outcomes, examples):
        energy = R.energy(scene, trajectory)
        change = (energy - energy[0]) / energy[0]
        drift = float(np.abs(change).max()) if np.isfinite(change).all() else math.inf
        contacts = _contacts(trajectory)
        tol = tumble_tolerance(scene, contacts)
        got = {"largest_energy_change": drift, "final_energy_change": float(change[-1]),
               "impacts": contacts, "tolerance": tol}
        measured[scene.name] = got
        outcome = classify_miss(drift, tol) if math.isfinite(drift) else "bug"
        example = dict(got)
        outcome = _law(engine, outcome, example)
        outcomes.append(outcome)
        if outcome is not None:
            examples.append({"class": outcome, **example, **scene.to_dict()})
    return tally("rigid", "elastic_tumble", outcomes, examples=examples, measured=measured,
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


# -- the textbook problems, as the report shows them ----------------------------------


@dataclass(frozen=True)
class TextbookProblem:
    """How one rigid check reads as a textbook problem: what it poses, and,
    from the check's ``measured`` (scene -> facts), two numbers, each the
    worst over the check's scenes: ``error``, the headline error against
    the closed form in ``unit``, and ``ratio``, the largest of the check's
    misses over their tolerances (every quantity the check gates on: at
    most 1 passes, as in the check)."""

    check: str
    problem: str
    unit: str
    error: Callable[[dict], float]
    ratio: Callable[[dict], float]


def _worst(measured: dict, value: Callable[[dict], float]) -> float:
    """The largest ``value`` over the scenes; nan when any is nan (a scene
    whose quantity could not be read), 0 scenes: nan."""
    values = [float(value(m)) for m in measured.values()]
    if not values or any(math.isnan(v) for v in values):
        return math.nan
    return max(values)


def _posed(measured: dict) -> dict:
    """``measured`` without its ``not_posed`` entry (scenes, not facts)."""
    return {k: v for k, v in measured.items() if k != "not_posed"}


def _oblique_ratio(m: dict) -> float:
    return max(abs(m["lateral_velocity"] - m["coulomb"]) / m["tolerance"],
               abs(m["spin"] - m["coulomb_spin"]) / m["spin_tolerance"])


def _free_ratio(m: dict) -> float:
    if m["flips"] != m["closed_form_flips"]:
        return math.inf
    return max(max(m["energy_drift"], m["momentum_drift"]) / FREE_ENERGY_TOL,
               m["interval_error"] / FLIP_INTERVAL_TOL)


def _free_error(m: dict) -> float:
    if m["flips"] != m["closed_form_flips"]:
        return math.inf
    return max(m["energy_drift"], m["momentum_drift"])


def _cradle_ratio(m: dict) -> float:
    return max(m["largest_miss_of_speed"] / CRADLE_TOL,
               m["energy_error"] / (2.0 * CRADLE_TOL), m["momentum_drift"] / MOMENTUM_TOL)


def _slide_ratio(m: dict) -> float:
    ratios = [abs(m["deceleration_over_mu_g"] - 1.0) / m["deceleration_tolerance"],
              abs(m["slip_end_time"] - m["closed_form_slip_end_time"])
              / m["slip_end_tolerance"]]
    if "distance" in m:
        ratios.append(abs(m["distance"] - m["closed_form_distance"]) / m["distance_tolerance"])
    return math.nan if any(math.isnan(r) for r in ratios) else max(ratios)


def _off_centre_ratio(m: dict) -> float:
    return max(m["largest_miss_of_closing_speed"] / OFF_CENTRE_TOL,
               m["momentum_drift"] / MOMENTUM_TOL)


#: The rigid checks that pose a problem with a closed-form answer, in the
#: order the report lists them.
TEXTBOOK_PROBLEMS = (
    TextbookProblem("rigid.apex_ratio", "drops: apex ratio e^2 over three bounces",
                    "relative error",
                    lambda m: _worst(m, lambda s: abs(s["relative_error"])),
                    lambda m: _worst(m, lambda s: abs(s["relative_error"]) / s["tolerance"])),
    TextbookProblem("rigid.no_spin", "symmetric frictionless landings: no spin",
                    "surface speed / impact speed",
                    lambda m: _worst(m, lambda s: s["surface_speed_fraction"]),
                    lambda m: _worst(m, lambda s: s["surface_speed_fraction"])
                    / NO_SPIN_FRACTION),
    TextbookProblem("rigid.oblique_bounce",
                    "oblique impacts, Coulomb friction over the impact (five regimes)",
                    "lateral velocity error, m/s",
                    lambda m: _worst(m, lambda s: abs(s["lateral_velocity"] - s["coulomb"])),
                    lambda m: _worst(m, _oblique_ratio)),
    TextbookProblem("rigid.spin_to_rest", "a cube spinning flat stops under friction",
                    "spin left after the limit, rad/s",
                    lambda m: _worst(m, lambda s: s["largest_spin_after_limit"]),
                    lambda m: _worst(m, lambda s: s["largest_spin_after_limit"])
                    / (SPIN_REST_FRACTION * R.SPIN)),
    TextbookProblem("rigid.free_rotation",
                    "torque-free brick near its middle axis: flips, energy, momentum",
                    "relative drift (inf: wrong flips)", lambda m: _worst(m, _free_error),
                    lambda m: _worst(m, _free_ratio)),
    TextbookProblem("rigid.off_centre", "a ball striking a free rod off its centre",
                    "largest miss / closing speed",
                    lambda m: _worst(m, lambda s: s["largest_miss_of_closing_speed"]),
                    lambda m: _worst(m, _off_centre_ratio)),
    TextbookProblem("rigid.incline", "a block on an incline slides by Coulomb or sticks",
                    "travel error, m",
                    lambda m: _worst(_posed(m), lambda s: s["miss_metres"]),
                    lambda m: _worst(_posed(m), lambda s: s["miss_metres"]
                                     / s["tolerance_metres"])),
    TextbookProblem("rigid.stack", "stable stacks and a cantilever stay put",
                    "largest vertex travel, m",
                    lambda m: _worst(m, lambda s: s["largest_vertex_travel_metres"]),
                    lambda m: _worst(m, lambda s: s["largest_vertex_travel_metres"])
                    / STACK_TRAVEL),
    TextbookProblem("rigid.cradle", "Newton's cradle: binary impacts hand the velocity on",
                    "largest miss / first ball's speed",
                    lambda m: _worst(m, lambda s: s["largest_miss_of_speed"]),
                    lambda m: _worst(m, _cradle_ratio)),
    TextbookProblem("rigid.slide_to_roll",
                    "a ball sliding into rolling, a box sliding to rest: deceleration mu g",
                    "deceleration error / mu g",
                    lambda m: _worst(m, lambda s: abs(s["deceleration_over_mu_g"] - 1.0)),
                    lambda m: _worst(m, _slide_ratio)),
    TextbookProblem("rigid.elastic_tumble", "a brick tumbling at e = 1: energy kept",
                    "relative energy change",
                    lambda m: _worst(m, lambda s: s["largest_energy_change"]),
                    lambda m: _worst(m, lambda s: s["largest_energy_change"]
                                     / s["tolerance"])),
    TextbookProblem("rigid.bounce_times", "drops: the times of the first three bounces",
                    "largest bounce-time miss, s",
                    lambda m: _worst(m, lambda s: s["largest_miss"]),
                    lambda m: _worst(m, lambda s: s["largest_miss"] / s["tolerance"])),
)
