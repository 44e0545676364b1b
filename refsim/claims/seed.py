"""The seed's claims C1-C12 and its terminology, as the report lists them.

The wording follows the seed's own text. Each claim is judged by
one function of this package (``refsim.claims.<area>.c<N>``); a claim
nobody has measured is shown as "not measured yet", never guessed.
"""

from __future__ import annotations

CLAIMS: dict[str, tuple[str, str]] = {
    # id: (area, the seed's claim)
    "C1": ("bounds", "Incremental and linear AABB update cost about the same until models "
                     "are large; incremental is clearly faster at 2000 triangles."),
    "C2": ("bounds", "The incremental AABB update needs a convex model."),
    "C3": ("collision", "The collision hierarchy trades accuracy for speed; coarse levels "
                        "are conservative."),
    "C4": ("collision", "Nearly parallel edges and planes \"did not seem to be a problem\"."),
    "C5": ("solvers", "Quadratic drag is not worth its extra cost over linear drag."),
    "C6": ("solvers", "Euler is unstable without enough damping: bodies jitter in resting "
                      "contact."),
    "C7": ("solvers", "The other four solvers behave alike in stability and accuracy."),
    "C8": ("solvers", "RK4 is not worth its cost in a particle system."),
    "C9": ("solvers", "\"Backwards Euler\" is the best general choice."),
    "C10": ("solvers", "Global error orders: Euler h, averaged Euler h^2, backwards Euler "
                       "h^2, midpoint h^2, RK4 h^4."),
    "C11": ("dynamics", "The body-body response lets slow or same-direction bodies "
                        "interpenetrate."),
    "C12": ("dynamics", "The angular velocity does not damp to rest."),
}

#: Where the seed's words differ from the standard terms.
TERMINOLOGY: tuple[tuple[str, str], ...] = (
    ("\"perfectly inelastic\" (body-body response)",
     "Exchanging the velocities of equal masses is a perfectly elastic collision "
     "(kinetic energy is kept); a perfectly inelastic one would leave both bodies "
     "with their common centre-of-mass velocity."),
    ("\"purely inelastic collisions appear too bouncy\"",
     "Means purely elastic collisions (restitution 1); restitution below 1 is what "
     "makes a collision inelastic."),
    ("\"Backwards Euler\"",
     "Not the implicit backward Euler method: two explicit Euler evaluations, the "
     "second one's slope applied from the start (an explicit two-stage method)."),
    ("\"Two-Step Averaged Euler\"",
     "Heun's method (the explicit trapezoidal rule), a one-step, two-stage method; "
     "not a two-step (multistep) method."),
    ("angular velocity in \"revolutions / time\"",
     "refsim uses radians per second throughout; w x X is a velocity "
     "only when w is in radians per unit time."),
)
