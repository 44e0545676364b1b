"""Checks of the ``rigid`` capability on lasting contact: a spin brought to
rest by friction, resting contact, stacks, a block on an incline, and
sliding into rolling or to rest.

The tolerances follow from what time-stepped contact allows
(:data:`~refsim.conformance.rigid_runs.CONTACT_STEPS`; the reasoning, and how a
miss is classified, are in :mod:`refsim.conformance.rigid_runs`).

- ``rigid.spin_to_rest`` (the cube spinning flat on the floor): by
  :func:`spin_rest_time` its angular speed is below
  :data:`SPIN_REST_FRACTION` of the initial one. Coulomb friction at the
  face brings it to rest in ``w0 I / (mu m g r)``, ``r`` the mean lever arm
  of the contact pressure: the face's corners, ``r = s / sqrt(2)``, for
  contact at the vertices; a uniform pressure over the face, ``r = 0.3826
  s``, is the slowest plausible distribution; the limit is twice that
  (0.89 s here).
- ``rigid.resting_contact`` (the resting cube; the spinning cube after it
  should have stopped): the lowest vertex is never deeper than
  :data:`REST_PENETRATION_STEPS` ``g h^2`` below the floor (gravity moves a
  resting body ``g h^2`` into the floor per step before a contact acts; a
  soft-contact engine holds a steady penetration of that order).
- ``rigid.incline`` (a block on an incline, sliding at 30 degrees with mu
  0.3, sticking at 10 degrees and at 50 degrees with mu 1.5): its travel
  down the slope in 1 s is Coulomb's
  (:func:`refsim.conformance.cases_rigid.incline_answer`) within
  :func:`incline_tolerance`: a first-order step's error ``a h t / 2`` in
  ``a t^2 / 2``, and friction that acts up to
  :data:`~refsim.conformance.rigid_runs.CONTACT_STEPS` steps late on each of
  the ``t / h`` steps of a resting contact, whose sliding speed gains
  ``g h`` per step before it acts: ``CONTACT_STEPS g h t`` (about 2 cm at
  h = 1e-3, where a frictionless block would slide metres). A scene the
  engine cannot pose is not posed, with the key.
- ``rigid.stack`` (a cube resting 0.3 m off the centre of another; a rod
  overhanging a cube, its centre of mass over the cube; a cube on a rod
  lying on the floor, 1.5 m from the rod's centre): every vertex of every
  body stays within :data:`STACK_TRAVEL` of where it started (each body is
  statically stable: the answer is that nothing moves).
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

Reference for the spin-down: the spin-down of a flat face under Coulomb
friction, e.g. K. L. Johnson, *Contact Mechanics*, Cambridge 1985, section
7.4 (torsion of a contact), with the mean distance of a square's points
from its centre, ``s (sqrt 2 + ln(1 + sqrt 2)) / 6``.
"""

from __future__ import annotations

import math
import time

import numpy as np

from refsim.conformance import cases_rigid as R
from refsim.conformance.results import CheckResult, classify_miss, not_applicable, tally
from refsim.conformance.rigid_runs import CONTACT_STEPS, _runs

#: The spinning cube counts as at rest below this fraction of its initial
#: angular speed (0.05 rad/s of 5): a hundredth of the motion is left, far
#: below what a reader of the trajectory would call spinning.
SPIN_REST_FRACTION = 0.01

#: The mean distance of a square's points from its centre, per unit side.
SQUARE_MEAN_RADIUS = (math.sqrt(2.0) + math.log(1.0 + math.sqrt(2.0))) / 6.0

#: The spin-down time limit is this many times the slowest plausible one.
SPIN_TIME_FACTOR = 2.0

#: Resting penetration allowed, in units of ``g h^2`` (one step's fall from rest).
REST_PENETRATION_STEPS = 10

#: How far a vertex of a resting stack may travel in its half second (m):
#: 1 mm in 2 s is creep a reader would see in a long run, at the same rate.
#: Resting contact settles within ``g h^2`` = 1e-5 m per step; a stable
#: solver stays within a few times that (pybullet's settling moves the
#: stacks 5e-5 to 1e-4 m in this half second).
STACK_TRAVEL = 2.5e-4


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
