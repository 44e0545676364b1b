"""The forces (seed S5): gravity and viscous drag, as accelerations, for rigid
bodies and particles alike.

What: for N points (body centroids or particles) with velocities ``v`` and
masses ``m``, ``a = (0, -g, 0) - (k / m) v`` (linear drag, the seed's choice)
or ``a = (0, -g, 0) - (k / m) |v| v`` (quadratic drag, the variant the seed
"tried and did not yield any significant results to justify the extra
computational expense", claim C5). Neither depends on position or time, and
neither acts on the rotation: the seed's "position and velocity is updated in
the normal fashion completely independent of rotational effects".

One arithmetic, in one order, for every path (bodies, the particle system's
in-place step and its compiled twin), so that they agree to the last bit:

- the drag rate ``r = k / m``, one division (per body, or once for the
  particles' common mass);
- ``|v|^2 = (vx vx + vy vy) + vz vz``, left to right (numpy's ``einsum``
  and ``linalg.norm`` pick their own order);
- linear: ``a = v (-r)``; quadratic: ``a = v (|v| (-r))``; then ``a_y -= g``.

Restitution and lateral friction, the seed's other two "forces", act only at
a collision: :mod:`refsim.dynamics.walls` (S7), :mod:`refsim.dynamics.rotation_seed`
(S9) and :mod:`refsim.dynamics.impulse` (the corrected model).

Seed section: S5 ("Gravity", "Viscous Drag"), for S7-S10.

Reference: J. R. Taylor, *Classical Mechanics*, University Science Books 2005,
chapter 2 (linear and quadratic air resistance).

Cost: O(N) per evaluation; a solver calls it once per stage.
"""

from __future__ import annotations

import numpy as np

from refsim.errors import check_option

DRAG_MODELS = ("linear", "quadratic")


def acceleration(v: np.ndarray, gravity: float, drag: float, mass,
                 drag_model: str = "linear") -> np.ndarray:
    """``dv/dt`` (N, 3) of points with velocities ``v`` (N, 3); a new array.

    Parameters
    ----------
    gravity : float
        Magnitude g; gravity is ``(0, -g, 0)`` (y up).
    drag : float
        The drag coefficient k (``world.drag``).
    mass : float or (N,) array
        One mass for all points (particles) or one per point (bodies).
    drag_model : {"linear", "quadratic"}
    """
    check_option("drag model", drag_model, DRAG_MODELS)
    r = drag / np.asarray(mass, dtype=np.float64)             # drag rate k/m
    if r.ndim:
        r = r[:, np.newaxis]
    if drag_model == "linear":
        a = v * (-r)
    else:
        speed = np.sqrt((v[:, 0] * v[:, 0] + v[:, 1] * v[:, 1]) + v[:, 2] * v[:, 2])
        a = v * (speed[:, np.newaxis] * (-r))
    a[:, 1] -= gravity
    return a


def acceleration_into(v: np.ndarray, gravity: float, drag: float, mass: float,
                      drag_model: str, out: np.ndarray, speed: np.ndarray) -> np.ndarray:
    """:func:`acceleration` for one common ``mass``, into ``out`` (N, 3),
    using ``speed`` (N,) as scratch for quadratic drag: the particle system's
    step, with no allocation of O(N) memory. The same operations in the same
    order, so the same bits."""
    r = drag / mass
    if drag_model == "linear":
        np.multiply(v, -r, out=out)
    elif drag_model == "quadratic":
        # |v|^2 = (vx vx + vy vy) + vz vz; out[:, 0] serves as scratch before
        # it receives its own value below.
        tmp = out[:, 0]
        np.multiply(v[:, 0], v[:, 0], out=speed)
        np.multiply(v[:, 1], v[:, 1], out=tmp)
        np.add(speed, tmp, out=speed)
        np.multiply(v[:, 2], v[:, 2], out=tmp)
        np.add(speed, tmp, out=speed)
        np.sqrt(speed, out=speed)
        np.multiply(speed, -r, out=speed)
        # Column by column: broadcasting speed[:, None] against (N, 3) makes
        # numpy allocate an (N, 3) temporary; three strided products do not.
        for axis in range(3):
            np.multiply(v[:, axis], speed, out=out[:, axis])
    else:
        check_option("drag model", drag_model, DRAG_MODELS)
    out[:, 1] -= gravity
    return out


def translational_rhs(gravity: float, drag: float, mass: np.ndarray, drag_model: str):
    """``f(t, y)`` of the translational ODE of B bodies of masses ``mass``
    (B,), for the seed's solvers.

    ``y`` is the flat state (2 B 3,): ``y.reshape(2, B, 3)[0]`` the centroids'
    positions, ``[1]`` their velocities; ``dy/dt = (v, a(v))``. One call
    evaluates every body (no per-body Python loop).
    """
    check_option("drag model", drag_model, DRAG_MODELS)
    n = len(mass)

    def f(t, y):
        Y = y.reshape(2, n, 3)
        dY = np.empty_like(Y)
        dY[0] = Y[1]
        dY[1] = acceleration(Y[1], gravity, drag, mass, drag_model)
        return dY.reshape(-1)

    return f


def field_rhs(accel: np.ndarray, drag: float, mass: np.ndarray, drag_model: str):
    """:func:`translational_rhs` in per-body uniform fields: ``accel`` (B, 3)
    is each body's constant acceleration (gravity along any direction and an
    applied force over the mass, :mod:`refsim.dynamics.loads`) in place of
    ``(0, -g, 0)``."""
    check_option("drag model", drag_model, DRAG_MODELS)
    n = len(mass)
    accel = np.asarray(accel, dtype=np.float64)

    def f(t, y):
        Y = y.reshape(2, n, 3)
        dY = np.empty_like(Y)
        dY[0] = Y[1]
        dY[1] = acceleration(Y[1], 0.0, drag, mass, drag_model) + accel
        return dY.reshape(-1)

    return f
