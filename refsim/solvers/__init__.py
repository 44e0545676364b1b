"""The seed's ODE solvers (S6): Butcher tableaux, one generic explicit
Runge-Kutta step, fixed-step integration, linear stability, measurements.

Modules: ``explicit_rk`` (the tableau type and the step), ``methods`` (the
five solvers and the seed's literal RK4 reading), ``integrate``
(``refsim.integrate``), ``stability`` (R(z) and stable step limits),
``problems`` (test equations with exact solutions), ``measure`` (order,
stability, work-precision numbers for claims C6, C7, C9, C10).
"""

from refsim.solvers.integrate import FixedStepResult, integrate, solve_fixed_step
from refsim.solvers.methods import SEED_LITERAL_VARIANTS, SOLVERS

__all__ = ["SOLVERS", "SEED_LITERAL_VARIANTS", "integrate", "solve_fixed_step",
           "FixedStepResult"]
