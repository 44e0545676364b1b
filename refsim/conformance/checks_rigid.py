"""The checks of the ``rigid`` capability, under the one name that the
registry and earlier scripts know them by: every public name of the
modules below, re-exported.

- :mod:`refsim.conformance.rigid_runs`: what the checks share (running an
  engine on the rigid scenes, tallying, classifying a miss, and the
  tolerances that follow from time-stepped contact, ``CONTACT_STEPS``);
- :mod:`refsim.conformance.checks_bounces`: impacts with the floor
  (``rigid.apex_ratio``, ``no_spin``, ``oblique_bounce``, ``energy``,
  ``determinism``, ``bounce_times``);
- :mod:`refsim.conformance.checks_contact`: lasting contact
  (``rigid.spin_to_rest``, ``resting_contact``, ``incline``, ``stack``,
  ``slide_to_roll``);
- :mod:`refsim.conformance.checks_rotation`: rotation
  (``rigid.free_rotation``, ``elastic_tumble``);
- :mod:`refsim.conformance.checks_strikes`: impacts between bodies
  (``rigid.off_centre``, ``cradle``);
- :mod:`refsim.conformance.textbook_problems`: the checks as textbook
  problems, as the report shows them (``TEXTBOOK_PROBLEMS``).
"""

from __future__ import annotations

from refsim.conformance.checks_bounces import (
    ARC_FRAMES,
    BOUNCE_TIME_STEPS,
    NO_SPIN_FRACTION,
    apex_tolerance,
    bounce_times,
    check_rigid_apex_ratio,
    check_rigid_bounce_times,
    check_rigid_determinism,
    check_rigid_energy,
    check_rigid_no_spin,
    check_rigid_oblique_bounce,
)
from refsim.conformance.checks_contact import (
    REST_PENETRATION_STEPS,
    SLIDE_WINDOW,
    SPIN_REST_FRACTION,
    SPIN_TIME_FACTOR,
    SQUARE_MEAN_RADIUS,
    STACK_TRAVEL,
    check_rigid_incline,
    check_rigid_resting_contact,
    check_rigid_slide_to_roll,
    check_rigid_spin_to_rest,
    check_rigid_stack,
    incline_tolerance,
    slide_facet_shift,
    slide_tolerance,
    slide_window,
    spin_rest_time,
)
from refsim.conformance.checks_rotation import (
    DRIFT_EXCUSE_LIMIT,
    DRIFT_ORDER_TOL,
    FLIP_INTERVAL_TOL,
    FREE_ENERGY_TOL,
    check_rigid_elastic_tumble,
    check_rigid_free_rotation,
    tumble_tolerance,
)
from refsim.conformance.checks_strikes import (
    CRADLE_TOL,
    MOMENTUM_TOL,
    OFF_CENTRE_TOL,
    check_rigid_cradle,
    check_rigid_off_centre,
)
from refsim.conformance.rigid_runs import (
    CONTACT_STEPS,
    FLIGHT_TOL,
    energy_tolerance,
)
from refsim.conformance.textbook_problems import (
    TEXTBOOK_PROBLEMS,
    TextbookProblem,
)

__all__ = [
    "CONTACT_STEPS",
    "energy_tolerance",
    "FLIGHT_TOL",
    "apex_tolerance",
    "ARC_FRAMES",
    "BOUNCE_TIME_STEPS",
    "bounce_times",
    "check_rigid_apex_ratio",
    "check_rigid_bounce_times",
    "check_rigid_determinism",
    "check_rigid_energy",
    "check_rigid_no_spin",
    "check_rigid_oblique_bounce",
    "NO_SPIN_FRACTION",
    "check_rigid_incline",
    "check_rigid_resting_contact",
    "check_rigid_slide_to_roll",
    "check_rigid_spin_to_rest",
    "check_rigid_stack",
    "incline_tolerance",
    "REST_PENETRATION_STEPS",
    "slide_facet_shift",
    "slide_tolerance",
    "SLIDE_WINDOW",
    "slide_window",
    "SPIN_REST_FRACTION",
    "spin_rest_time",
    "SPIN_TIME_FACTOR",
    "SQUARE_MEAN_RADIUS",
    "STACK_TRAVEL",
    "check_rigid_elastic_tumble",
    "check_rigid_free_rotation",
    "DRIFT_EXCUSE_LIMIT",
    "DRIFT_ORDER_TOL",
    "FLIP_INTERVAL_TOL",
    "FREE_ENERGY_TOL",
    "tumble_tolerance",
    "check_rigid_cradle",
    "check_rigid_off_centre",
    "CRADLE_TOL",
    "MOMENTUM_TOL",
    "OFF_CENTRE_TOL",
    "TEXTBOOK_PROBLEMS",
    "TextbookProblem",
]
