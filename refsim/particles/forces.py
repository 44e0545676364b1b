"""The forces on a particle (S5): gravity and viscous drag, as accelerations.

What: ``a(v) = (0, -g, 0) - (k/m) v`` (linear drag, the seed's choice) or
``a(v) = (0, -g, 0) - (k/m) |v| v`` (quadratic drag, the variant the seed
"tried and did not yield any significant results to justify the extra
computational expense", claim C5). Neither depends on position or time.

Seed section: S5 ("Gravity", "Viscous Drag"), used by S10.

Reference: the drag laws as in any mechanics text, e.g. J. R. Taylor,
*Classical Mechanics*, University Science Books 2005, chapter 2 (linear
and quadratic air resistance).

Cost: O(N). Linear drag: one multiply-add per component. Quadratic drag: the
speed ``|v|`` as well (3 multiplies, 2 adds, a square root per particle).

Two forms with the same arithmetic in the same order, so their results are
equal to the last bit: :func:`acceleration` returns a new array (the plain
kernel); :func:`acceleration_into` writes into preallocated buffers (the
particle system's fast path).
"""

from __future__ import annotations

import numpy as np


def acceleration(v: np.ndarray, gravity: float, drag: float, mass: float,
                 drag_model: str) -> np.ndarray:
    """``dv/dt`` for velocities ``v`` (N, 3); returns a new (N, 3) array."""
    r = drag / mass                                  # drag rate k/m
    if drag_model == "linear":
        a = v * (-r)
    elif drag_model == "quadratic":
        # |v| summed in a fixed order, (vx vx + vy vy) + vz vz, which every
        # path (acceleration_into, the compiled Euler step) repeats exactly;
        # numpy's einsum would pick its own order.
        speed = np.sqrt((v[:, 0] * v[:, 0] + v[:, 1] * v[:, 1]) + v[:, 2] * v[:, 2])
        a = v * (speed * (-r))[:, np.newaxis]
    else:
        raise ValueError(f"unknown drag model {drag_model!r}")
    a[:, 1] -= gravity
    return a


def acceleration_into(v: np.ndarray, gravity: float, drag: float, mass: float,
                      drag_model: str, out: np.ndarray, speed: np.ndarray) -> np.ndarray:
    """:func:`acceleration` into ``out`` (N, 3), using ``speed`` (N,) as scratch
    for quadratic drag. No allocation of O(N) memory."""
    r = drag / mass
    if drag_model == "linear":
        np.multiply(v, -r, out=out)
    elif drag_model == "quadratic":
        # |v|^2 = (vx vx + vy vy) + vz vz, as in acceleration(); out[:, 0]
        # serves as scratch before it receives its own value below.
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
        raise ValueError(f"unknown drag model {drag_model!r}")
    out[:, 1] -= gravity
    return out
