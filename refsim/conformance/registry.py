"""The checks, one per property, and the case sets they run on.

Each :class:`Check` names its capability (:data:`refsim.engines.CAPABILITIES`),
the case set it needs and the function that runs it. The case sets are
built once per run and shared by every check and every engine that uses
them (:func:`build_cases`): a run of several engines computes each exact
answer once.

=====================  ==========  =========================================
check                  cases       property
=====================  ==========  =========================================
triangles.reference    triangles   refsim's edge-triangle test agrees with
                                   the rational separating-axis test (the
                                   ground truth, checked twice)
triangles.agreement    triangles   the engine's answer is the exact one
pairs.agreement        poses       the exact set of intersecting face pairs
collide.agreement      poses       true exactly when the surfaces meet
aabb.encloses          boxes       contains every exactly transformed vertex
aabb.tight             boxes       no larger than the exact box
ode.order              ode         observed order is the declared one
ode.stability          ode         realises its declared R(z)
ode.evaluations        ode         evaluations of f per step
rigid.apex_ratio       rigid       apex ratio e^2
rigid.no_spin          rigid       a symmetric frictionless landing does
                                   not turn the body
rigid.oblique_bounce   rigid       Coulomb's lateral velocity
rigid.spin_to_rest     rigid       friction stops a spin
rigid.energy           rigid       energy never rises
rigid.resting_contact  rigid       no interpenetration at rest
rigid.determinism      rigid       two runs, the same bits
rigid.free_rotation    rigid       torque-free flips and energy
rigid.off_centre       rigid       an off-centre strike's impulse solution
rigid.incline          rigid       Coulomb's incline: slide or stick
rigid.stack            rigid       stable stacks stay where they are
rigid.cradle           rigid       Newton's cradle: binary impacts hand
                                   the velocity down the row
rigid.slide_to_roll    rigid       a sliding body decelerates at mu g
                                   until it rolls (ball) or stops (cube)
rigid.elastic_tumble   rigid       a brick tumbling at e = 1 keeps its
                                   energy
rigid.bounce_times     rigid       bounces at the closed form's times
=====================  ==========  =========================================

``--cases N`` sizes the generated sets (triangles, poses, boxes); the ODE
problems and the rigid scenes are fixed sets.

Cost: building a case set is the cost its module states (the exact answers
dominate it; measured times in docs/decisions/conformance.md); the rigid set
is about 37,500 steps per engine; the registry itself is O(checks).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from refsim.conformance import checks_bounces as RB
from refsim.conformance import checks_contact as RC
from refsim.conformance import checks_geometry as G
from refsim.conformance import checks_ode as O
from refsim.conformance import checks_rotation as RR
from refsim.conformance import checks_strikes as RS

CASE_SETS = ("triangles", "poses", "boxes", "ode", "rigid")


@dataclass(frozen=True)
class Check:
    """A check: its capability and name, the case set it runs on, its
    function, an engine attribute it needs beyond the capability
    (``requires``; without it the check reports ``n/a``), and the unit of
    the gap or excess it measures per failing case (``miss_unit``: "metres"
    for the geometric checks, which an expected-failures bound is in; None
    for checks that measure no length)."""

    capability: str
    name: str
    cases: str
    run: Callable
    requires: str | None = None
    miss_unit: str | None = None

    @property
    def key(self) -> str:
        return f"{self.capability}.{self.name}"

    @property
    def doc(self) -> str:
        """The first paragraph of the check function's docstring, on one
        line, without reStructuredText's double backquotes."""
        paragraph = (self.run.__doc__ or "").strip().split("\n\n")[0]
        return " ".join(paragraph.split()).replace("``", "")


CHECKS: tuple[Check, ...] = (
    Check("triangles", "reference", "triangles", G.check_triangles_reference, miss_unit="metres"),
    Check("triangles", "agreement", "triangles", G.check_triangles_agreement, miss_unit="metres"),
    Check("pairs", "agreement", "poses", G.check_pairs_agreement, miss_unit="metres"),
    Check("collide", "agreement", "poses", G.check_collide_agreement, miss_unit="metres"),
    Check("aabb", "encloses", "boxes", G.check_aabb_encloses, miss_unit="metres"),
    Check("aabb", "tight", "boxes", G.check_aabb_tight, miss_unit="metres"),
    Check("ode", "order", "ode", O.check_ode_order),
    Check("ode", "stability", "ode", O.check_ode_stability, requires="ode_stability"),
    Check("ode", "evaluations", "ode", O.check_ode_evaluations),
    Check("rigid", "apex_ratio", "rigid", RB.check_rigid_apex_ratio),
    Check("rigid", "no_spin", "rigid", RB.check_rigid_no_spin),
    Check("rigid", "oblique_bounce", "rigid", RB.check_rigid_oblique_bounce),
    Check("rigid", "spin_to_rest", "rigid", RC.check_rigid_spin_to_rest),
    Check("rigid", "energy", "rigid", RB.check_rigid_energy),
    Check("rigid", "resting_contact", "rigid", RC.check_rigid_resting_contact),
    Check("rigid", "determinism", "rigid", RB.check_rigid_determinism),
    Check("rigid", "free_rotation", "rigid", RR.check_rigid_free_rotation),
    Check("rigid", "off_centre", "rigid", RS.check_rigid_off_centre),
    Check("rigid", "incline", "rigid", RC.check_rigid_incline, miss_unit="metres"),
    Check("rigid", "stack", "rigid", RC.check_rigid_stack, miss_unit="metres"),
    Check("rigid", "cradle", "rigid", RS.check_rigid_cradle),
    Check("rigid", "slide_to_roll", "rigid", RC.check_rigid_slide_to_roll),
    Check("rigid", "elastic_tumble", "rigid", RR.check_rigid_elastic_tumble),
    Check("rigid", "bounce_times", "rigid", RB.check_rigid_bounce_times),
)

CHECK_KEYS = tuple(c.key for c in CHECKS)

#: Checks of the kit's own ground truth that do not call the engine (shown
#: apart in the tables and pages, so that their pass is not read as the
#: engine's).
TRUTH_CHECKS = ("triangles.reference",)


def check_by_key(key: str) -> Check:
    """The check ``capability.check`` (KeyError for an unknown one)."""
    for check in CHECKS:
        if check.key == key:
            return check
    raise KeyError(key)


def checks_for(capabilities) -> tuple[Check, ...]:
    """The checks of the given capabilities, in :data:`CHECKS` order."""
    wanted = set(capabilities)
    return tuple(c for c in CHECKS if c.capability in wanted)


#: The generated sets (``--cases`` sizes them); the others are fixed.
GENERATED_SETS = ("triangles", "poses", "boxes")


def generated_range(set_name: str, n: int, seed: int, start: int = 0,
                    stop: int | None = None):
    """Cases ``start`` to ``stop - 1`` (default: all ``n``) of generated set
    ``set_name`` of ``n`` cases from ``seed``; an empty range gives an empty
    set, which still knows its Hypothesis strategy and seed."""
    from refsim.conformance.cases_boxes import box_cases
    from refsim.conformance.cases_meshes import pose_cases
    from refsim.conformance.cases_triangles import triangle_cases

    build = {"triangles": triangle_cases, "poses": pose_cases, "boxes": box_cases}[set_name]
    return build(n, seed, start, stop)


def build_cases(needed, n: int, seed: int) -> dict:
    """The case sets named in ``needed`` (a subset of :data:`CASE_SETS`),
    ``n`` cases in each generated set, from ``seed``; the generated sets
    are read from the disk cache when they were built before
    (:mod:`refsim.conformance.case_cache`)."""
    from refsim.conformance.case_cache import cached
    from refsim.conformance.cases_ode import ode_cases
    from refsim.conformance.cases_rigid import rigid_cases

    def build(name: str):
        if name in GENERATED_SETS:
            return cached(name, n, seed, lambda: generated_range(name, n, seed))
        return ode_cases(seed) if name == "ode" else rigid_cases(seed)

    return {name: build(name) for name in CASE_SETS if name in set(needed)}
