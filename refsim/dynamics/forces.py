"""The forces on the bodies (seed S5): gravity and viscous drag, as accelerations.

What: for B bodies at once, ``a = (0, -g, 0) - (k / m) v`` (linear drag, the
seed's choice) or ``a = (0, -g, 0) - (k / m) |v| v`` (quadratic drag, the
variant the seed "tried and did not yield any significant results to justify
the extra computational expense", claim C5). The same laws as the particle
system's (:mod:`refsim.particles.forces`), with one mass per body instead of
one for all particles. Neither force acts on the rotation: the seed's
"position and velocity is updated in the normal fashion completely
independent of rotational effects".

Restitution and lateral friction, the seed's other two "forces", act only at
a collision; they live in :mod:`refsim.dynamics.walls` (S7),
:mod:`refsim.dynamics.rotation_seed` (S9) and
:mod:`refsim.dynamics.impulse` (the corrected model).

Seed section: S5 ("Gravity", "Viscous Drag").

Reference: J. R. Taylor, *Classical Mechanics*, University Science Books 2005,
chapter 2 (linear and quadratic air resistance).

Cost: O(B) per evaluation; the solver calls it once per stage.
"""

from __future__ import annotations

import numpy as np

DRAG_MODELS = ("linear", "quadratic")


def acceleration(v: np.ndarray, gravity: float, drag: float, inv_mass: np.ndarray,
                 drag_model: str = "linear") -> np.ndarray:
    """``dv/dt`` (B, 3) of bodies with velocities ``v`` (B, 3).

    Parameters
    ----------
    gravity : float
        Magnitude g; gravity is ``(0, -g, 0)`` (y up).
    drag : float
        The drag coefficient k (``world.drag``).
    inv_mass : (B,) array
        ``1 / m`` of each body.
    drag_model : {"linear", "quadratic"}
    """
    r = drag * inv_mass                                     # drag rate k/m, (B,)
    if drag_model == "linear":
        a = v * (-r)[:, np.newaxis]
    elif drag_model == "quadratic":
        speed = np.sqrt(np.einsum("ij,ij->i", v, v))
        a = v * (-r * speed)[:, np.newaxis]
    else:
        raise ValueError(f"unknown drag model {drag_model!r}; expected one of {DRAG_MODELS}")
    a[:, 1] -= gravity
    return a


def translational_rhs(gravity: float, drag: float, inv_mass: np.ndarray, drag_model: str):
    """``f(t, y)`` of the translational ODE of all bodies, for the seed's solvers.

    ``y`` is the flat state (2 B 3,): ``y.reshape(2, B, 3)[0]`` the centroids'
    positions, ``[1]`` their velocities; ``dy/dt = (v, a(v))``. One call
    evaluates every body (no per-body Python loop).
    """
    n = len(inv_mass)

    def f(t, y):
        Y = y.reshape(2, n, 3)
        dY = np.empty_like(Y)
        dY[0] = Y[1]
        dY[1] = acceleration(Y[1], gravity, drag, inv_mass, drag_model)
        return dY.reshape(-1)

    return f
