"""diffrax's fixed-step explicit Runge--Kutta solvers as refsim engines (capability ``ode``).

Library: diffrax 0.7.2 (JAX, CPU, float64 via ``jax.config.update("jax_enable_x64", True)``).

What it wraps. One step ``ode_step(f, t, y, h)`` is one call of diffrax's public
driver::

    diffrax.diffeqsolve(diffrax.ODETerm(vf), solver, t0=t, t1=t + h, dt0=h, y0=y,
                        stepsize_controller=diffrax.ConstantStepSize(),
                        saveat=diffrax.SaveAt(t1=True))

compiled once per engine and state shape with ``jax.jit``. The kit's ``f`` is plain
Python on numpy arrays, so the vector field ``vf`` reaches it through
``jax.pure_callback`` (it runs on the host with concrete float64 arrays; JAX never
traces it). ``diffeqsolve`` with ``t1 - t0 == dt0`` takes exactly one step.

One factory per solver: ``euler``, ``heun``, ``midpoint``, ``ralston``, ``bosh3``,
``tsit5``, ``dopri5``; ``make_engine`` is ``tsit5`` (diffrax's recommended default).

Declarations, each from diffrax's documentation
(https://docs.kidger.site/diffrax/api/solvers/ode_solvers/, the same text as each
class's docstring):

- ``ode_order``: "Euler's method. 1st order explicit Runge--Kutta method";
  Heun, Midpoint, Ralston: "2nd order explicit Runge--Kutta method";
  Bosh3: "3rd order explicit Runge--Kutta method"; Tsit5: "5th order explicit
  Runge--Kutta method"; Dopri5: "5th order Runge--Kutta method".
- ``ode_stability(z)``: R(z) = 1 + z b^T (I - z A)^{-1} 1, the stability function of
  an explicit Runge--Kutta method, computed from the Butcher tableau diffrax exposes
  as ``solver.tableau`` (``diffrax.ButcherTableau``: ``c``, ``b_sol``, ``a_lower``,
  the strictly lower rows of A from the second stage on). ``Euler`` exposes no
  tableau; its documented 1-stage method is ``y + h f(t, y)``, so R(z) = 1 + z.
- ``distance_tolerance``, ``box_slack``, ``contact_law``: not declared (they concern
  geometry and contact, not this capability).
"""

from __future__ import annotations

import jax

jax.config.update("jax_enable_x64", True)
jax.config.update("jax_platforms", "cpu")

import diffrax  # noqa: E402
import jax.numpy as jnp  # noqa: E402
import numpy as np  # noqa: E402

#: The order each solver's documentation states (see the module docstring).
DOCUMENTED_ORDER = {"Euler": 1, "Heun": 2, "Midpoint": 2, "Ralston": 2, "Bosh3": 3,
                    "Tsit5": 5, "Dopri5": 5}


def butcher_matrices(solver_class) -> tuple[np.ndarray, np.ndarray]:
    """A (s, s) and b (s,) of ``solver_class.tableau``; ``Euler`` (no tableau): A = [0],
    b = [1], its documented one stage."""
    tableau = getattr(solver_class, "tableau", None)
    if tableau is None:
        return np.zeros((1, 1)), np.ones(1)
    b = np.asarray(tableau.b_sol, dtype=np.float64)
    A = np.zeros((len(b), len(b)))
    for i, row in enumerate(tableau.a_lower):
        A[i + 1, :len(row)] = row
    return A, b


class DiffraxEngine:
    """One diffrax solver, stepped once per ``ode_step`` call."""

    def __init__(self, solver_class):
        self.solver_class = solver_class
        self.name = f"diffrax-{solver_class.__name__.lower()}"
        self.ode_order = DOCUMENTED_ORDER[solver_class.__name__]
        self._A, self._b = butcher_matrices(solver_class)
        self._f = None                    # the kit's f of the step under way
        self._step = jax.jit(self._solve)

    def _host_f(self, t, y):
        out = self._f(float(t), np.asarray(y, dtype=np.float64).copy())
        return np.asarray(out, dtype=np.float64).reshape(np.shape(y))

    def _solve(self, t, y, h):
        def vf(t, y, args):
            shape = jax.ShapeDtypeStruct(y.shape, jnp.float64)
            return jax.pure_callback(self._host_f, shape, t, y)

        sol = diffrax.diffeqsolve(
            diffrax.ODETerm(vf), self.solver_class(), t0=t, t1=t + h, dt0=h, y0=y,
            stepsize_controller=diffrax.ConstantStepSize(),
            saveat=diffrax.SaveAt(t1=True), max_steps=4)
        return sol.ys[0]

    def ode_step(self, f, t, y, h):
        y = np.asarray(y, dtype=np.float64)
        scalar = y.ndim == 0
        self._f = (lambda t, y: f(t, y[0])) if scalar else f
        out = self._step(jnp.float64(t), jnp.asarray(y.reshape(1) if scalar else y),
                         jnp.float64(h))
        out = np.asarray(out, dtype=np.float64)
        return float(out[0]) if scalar else out

    def ode_stability(self, z):
        z = complex(z)
        s = len(self._b)
        k = np.linalg.solve(np.eye(s) - z * self._A, np.ones(s, dtype=complex))
        return complex(1 + z * (self._b @ k))


def euler():
    return DiffraxEngine(diffrax.Euler)


def heun():
    return DiffraxEngine(diffrax.Heun)


def midpoint():
    return DiffraxEngine(diffrax.Midpoint)


def ralston():
    return DiffraxEngine(diffrax.Ralston)


def bosh3():
    return DiffraxEngine(diffrax.Bosh3)


def tsit5():
    return DiffraxEngine(diffrax.Tsit5)


def dopri5():
    return DiffraxEngine(diffrax.Dopri5)


make_engine = tsit5
