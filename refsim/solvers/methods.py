"""The seed's five ODE solvers (S6) as Butcher tableaux.

What: the tableaux of "Euler", "Two-Step Averaged Euler", "Backwards Euler",
"Midpoint" and "4th-Order Runge-Kutta" exactly as the seed's section
"Differential Equation Solvers" defines them, plus the seed's RK4 weights
read literally (:data:`SEED_LITERAL_VARIANTS`), which are a typo.

Seed section: S6; claim C10 is each method's ``seed_order``
against its derived ``order``.

Reference: E. Hairer, S. P. Norsett, G. Wanner, *Solving Ordinary Differential
Equations I*, 2nd ed., Springer 1993, section II.1 (Euler, Runge's midpoint
method, Heun's method, the classical "RK4" of Kutta 1901) and
II.2 (order conditions); J. C. Butcher, *Numerical Methods for Ordinary
Differential Equations*, 3rd ed., Wiley 2016, chapter 2 (Runge-Kutta
methods, low orders).

Cost per step: 1 (euler), 2 (averaged-euler, backwards-euler, midpoint) and
4 (rk4) evaluations of ``f``.

Each tableau is written ``c | A`` over ``| b``. The seed speaks of "steps" and
"derivatives"; here a stage derivative is ``k_i`` and the step is
``y1 = y0 + h sum_i b_i k_i``.
"""

from __future__ import annotations

from types import MappingProxyType

from refsim.solvers.explicit_rk import ExplicitRungeKutta

EULER = ExplicitRungeKutta(
    name="euler",
    title="explicit (forward) Euler",
    #   0 |
    #   --+--
    #     | 1
    A=[[0]], b=[1], c=[0],
    seed_text=("Euler: The step, or increment, to the next state vector is equal to the "
               "derivative of the current step vector."),
    seed_order=1,
)
"""y1 = y0 + h f(t0, y0)."""

AVERAGED_EULER = ExplicitRungeKutta(
    name="averaged-euler",
    title="Heun's method (explicit trapezoidal rule)",
    #   0 |
    #   1 | 1
    #   --+---------
    #     | 1/2 1/2
    A=[[0, 0], [1, 0]], b=["1/2", "1/2"], c=[0, 1],
    seed_text=("Two-Step Averaged Euler: The step for the current state vector is equal to "
               "its derivative. The next state vector is computed using an Euler step, and "
               "the step for this state vector is also computed. The average of these two "
               "steps is used as the step for the original state vector."),
    seed_order=2,
)
"""k1 = f(t0, y0); k2 = f(t0 + h, y0 + h k1); y1 = y0 + h (k1 + k2) / 2."""

BACKWARDS_EULER = ExplicitRungeKutta(
    name="backwards-euler",
    title="explicit Euler-predicted backward Euler (one fixed-point correction, PEC)",
    #   0 |
    #   1 | 1
    #   --+------
    #     | 0  1
    A=[[0, 0], [1, 0]], b=[0, 1], c=[0, 1],
    seed_text=("Backwards Euler: Two Euler steps are performed and the second step is used "
               "as a step for the original state vector."),
    seed_order=2,
)
"""k1 = f(t0, y0); k2 = f(t0 + h, y0 + h k1); y1 = y0 + h k2.

This is not the implicit backward Euler method ``y1 = y0 + h f(t1, y1)``. It
is that formula with ``y1`` on the right replaced by the forward Euler
predictor ``y0 + h k1``: backward Euler with its implicit equation solved by
one fixed-point iteration from an Euler start (predict, evaluate, correct).
That justifies the seed's name; the method itself is an explicit two-stage
Runge-Kutta method with ``c = (0, 1)``, ``a21 = 1``, ``b = (0, 1)``.

The second derivative is evaluated at the end of the step, time ``t0 + h``,
because the state it is evaluated at is the Euler step's end point (the
"second step" is the derivative there). Evaluating it at ``t0`` would make
the method treat time and state differently (``c2 != a21``).

Order (HNW I, II.2): ``sum b_i = 1`` holds, ``sum b_i c_i = 1 != 1/2``
fails, so the method is first order, not second as the seed states (C10).
Its local error is ``+h^2 y''/2 + O(h^3)``, the same leading term as the
implicit backward Euler method and the opposite sign to forward Euler.

Stability function: ``R(z) = 1 + z + z^2``, the implicit method's
``1/(1 - z)`` truncated after ``z^2``. On the negative real axis it is stable
for ``-1 <= z <= 0`` (half of forward Euler's interval), and on the imaginary
axis ``|R(iy)|^2 = 1 - y^2 + y^4 <= 1`` for ``|y| <= 1``: it damps an
undamped oscillation, like the implicit method, whereas forward Euler, Heun
and midpoint amplify it at every step size.
"""

MIDPOINT = ExplicitRungeKutta(
    name="midpoint",
    title="explicit midpoint rule (Runge 1895)",
    #   0   |
    #   1/2 | 1/2
    #   ----+--------
    #       | 0    1
    A=[[0, 0], ["1/2", 0]], b=[0, 1], c=[0, "1/2"],
    seed_text=("Midpoint: One half of an Euler step is performed, the step is computed at "
               "this midpoint, and used as a step from the original state vector."),
    seed_order=2,
)
"""k1 = f(t0, y0); k2 = f(t0 + h/2, y0 + (h/2) k1); y1 = y0 + h k2."""

RK4 = ExplicitRungeKutta(
    name="rk4",
    title="classical Runge-Kutta method (Kutta 1901)",
    #   0   |
    #   1/2 | 1/2
    #   1/2 | 0    1/2
    #   1   | 0    0    1
    #   ----+-------------------
    #       | 1/6  1/3  1/3  1/6
    A=[[0, 0, 0, 0], ["1/2", 0, 0, 0], [0, "1/2", 0, 0], [0, 0, 1, 0]],
    # DEVIATION: the seed's weights are "one-sixth of step1 + two-thirds of
    # step2 + two-thirds of step3 + one-sixth of step4", which sum to 5/3; a
    # consistent method needs sum b = 1, and the O(h^4) the seed states needs
    # the classical 1/6, 1/3, 1/3, 1/6. The literal reading is kept as
    # SEED_LITERAL_VARIANTS["rk4-seed-literal"].
    b=["1/6", "1/3", "1/3", "1/6"],
    c=[0, "1/2", "1/2", 1],
    seed_text=("Step1 is computed as a normal Euler step; Step2 is computed as the "
               "derivative of the state vector, computed by travelling half of step 1 from "
               "the original state vector; Step3 ... travelling half of step 2 ...; Step4 "
               "... travelling a full step 3 from the original state vector. The resulting "
               "step is computed as a linear combination of steps 1-4 as follows: "
               "one-sixth of step1 + two-thirds of step2 + two-thirds of step3 + one-sixth "
               "of step4."),
    seed_order=4,
)
"""k1 = f(t0, y0); k2 = f(t0 + h/2, y0 + (h/2) k1); k3 = f(t0 + h/2, y0 + (h/2) k2);
k4 = f(t0 + h, y0 + h k3); y1 = y0 + h (k1 + 2 k2 + 2 k3 + k4) / 6."""

RK4_SEED_LITERAL = ExplicitRungeKutta(
    name="rk4-seed-literal",
    title="RK4 with the seed's literal weights 1/6, 2/3, 2/3, 1/6 (inconsistent)",
    A=RK4.A, c=RK4.c,
    b=["1/6", "2/3", "2/3", "1/6"],
    seed_text=RK4.seed_text,
    seed_order=4,
)
"""The seed's RK4 sentence read literally: ``sum b = 5/3``.

Inconsistent (order 0): one step is ``y0 + (5/3) h f(t0, y0) + O(h^2)``, so as
``h -> 0`` it converges to the solution of ``y' = (5/3) f(t, y)``, not of
``y' = f``. Its stability function is ``1 + 5/3 z + 5/6 z^2 + 1/4 z^3 +
1/24 z^4``. Written in terms of ``g = (5/3) f`` it is a 4-stage method with
weights ``(1/10, 2/5, 2/5, 1/10)`` and ``sum b_i c_i = 3/10``: first order for
that scaled equation (:func:`refsim.studies.solvers.measure_seed_literal_rk4`
measures both).
"""

#: The seed's five solvers, by the key used in scene files and the public API.
SOLVERS = MappingProxyType({m.name: m for m in (EULER, AVERAGED_EULER, BACKWARDS_EULER,
                                                MIDPOINT, RK4)})

#: Literal readings of the seed that are kept for measurement, not for use.
SEED_LITERAL_VARIANTS = MappingProxyType({RK4_SEED_LITERAL.name: RK4_SEED_LITERAL})
