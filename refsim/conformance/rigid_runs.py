"""What the checks of the ``rigid`` capability share: how they run an engine on
the rigid scenes and tally the outcomes, how a miss is classified, and the
tolerances that follow from time-stepped contact. The checks themselves are in
:mod:`~refsim.conformance.checks_bounces`,
:mod:`~refsim.conformance.checks_contact`,
:mod:`~refsim.conformance.checks_rotation` and
:mod:`~refsim.conformance.checks_strikes`.

Every tolerance below follows from one fact about time-stepped contact: an
engine finds a contact only at a step, so a bounce can happen up to a step
late and be resolved over a step or two. With :data:`CONTACT_STEPS` = 2
steps of size ``h`` at impact speed ``v`` the bounce point can move by up to
``2 v h``, and a friction impulse spread over those steps can include
gravity's ``m g h`` per step. refsim's corrected model meets the answers to
rounding; first-order engines (Bullet, MuJoCo: semi-implicit Euler) must
meet them within these bounds.

A failure within twice its tolerance is "tolerance"; beyond, "bug" (unless
recognised as its check's module says). An engine that declares a contact law
other than a restitution coefficient (``contact_law``,
:func:`refsim.engines.declarations`) is not held to the answers that assume
one: its misses of ``rigid.apex_ratio``, ``rigid.oblique_bounce``,
``rigid.cradle``, ``rigid.elastic_tumble`` and ``rigid.bounce_times`` are
"law", naming it. An apex ratio or bounce times that cannot be read (fewer
bounces than they need) are "unmeasurable", with the reason. A scene whose
``simulate`` raises, or returns arrays of other shapes than the contract's, is
that scene's "crash" in every check that reads it.

References: the analytic answers of :mod:`refsim.dynamics.analytic`
(Mirtich 1996, ch. 3; Stronge, *Impact Mechanics*, 2000); the spin-down's
in :mod:`~refsim.conformance.checks_contact`.

Cost: the runs of :mod:`refsim.conformance.cases_rigid` (shared between the
checks) plus two reruns for ``rigid.determinism``; ``rigid.bounce_times`` reads
the drops' runs, and
:func:`~refsim.conformance.checks_contact.slide_facet_shift` turns the sphere
mesh's vertices (1,002) through 2,001 angles per slide scene. """

from __future__ import annotations

import math

import numpy as np

from refsim.conformance import cases_rigid as R
from refsim.conformance.results import Crash, attempt

#: Steps over which an engine may find and resolve one contact (module docstring).
CONTACT_STEPS = 2


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
