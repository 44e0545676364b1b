"""The rigid checks that pose a problem with a closed-form answer, as the
report's textbook section shows them (:data:`TEXTBOOK_PROBLEMS`): what each
poses, and from the check's ``measured`` facts, its headline error and its
worst miss over its tolerance, each the worst over the check's scenes.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

from refsim.conformance import cases_rigid as R
from refsim.conformance.checks_bounces import NO_SPIN_FRACTION
from refsim.conformance.checks_contact import SPIN_REST_FRACTION, STACK_TRAVEL
from refsim.conformance.checks_rotation import FLIP_INTERVAL_TOL, FREE_ENERGY_TOL
from refsim.conformance.checks_strikes import CRADLE_TOL, MOMENTUM_TOL, OFF_CENTRE_TOL


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
