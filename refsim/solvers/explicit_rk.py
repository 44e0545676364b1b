"""One step of an explicit Runge-Kutta method given by its Butcher tableau.

What: a method is data, an :class:`ExplicitRungeKutta` holding its tableau
(``A``, ``b``, ``c``) as exact fractions, and :func:`rk_step` is the one piece
of arithmetic every method shares. The seed's five solvers (S6) are five
tableaux in :mod:`refsim.solvers.methods`.

Reference: E. Hairer, S. P. Norsett, G. Wanner, *Solving Ordinary Differential
Equations I*, 2nd ed., Springer 1993, section II.1 (the tableau notation)
and II.2 (order conditions: the rooted trees up to order 4); J. C. Butcher,
*Numerical Methods for Ordinary Differential Equations*, 3rd ed., Wiley 2016,
chapter 3 (trees and order conditions). Layout after scipy's
``integrate/_ivp/rk.py``: the class carries the tableau and its order, the
step does the arithmetic.

Notation: for a step of size ``h`` from ``(t, y)``::

    k_i = f(t + c_i h, y + h sum_{j<i} a_ij k_j),   i = 1..s
    y_next = y + h sum_i b_i k_i

Cost: ``s`` evaluations of ``f`` per step (``s`` = ``stages``) and O(s^2 d)
arithmetic for a state of ``d`` numbers.

Order: the order conditions are checked exactly, in rational arithmetic, for
the rooted trees up to order 4. An explicit method with ``s`` stages has order
at most ``s``: the condition of the "tall" tree of order ``s + 1`` is
``b^T A^(s-1) c = 1/(s+1)!``, but ``A`` is strictly lower triangular, so
``A^(s-1) c = A^s 1 = 0``. Every method here has ``s <= 4``, so checking the
trees up to order 4 gives the order exactly, not only a lower bound.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from fractions import Fraction

import numpy as np

# The rooted trees up to order 4 as (order, name, sum, required value), with
# c_i = sum_j a_ij (HNW I, section II.2; Butcher 2016, chapter 3).
# Each "sum" is a function of (A, b, c) in exact fractions.


def _dot(u, v):
    return sum((ui * vi for ui, vi in zip(u, v, strict=True)), Fraction(0))


def _matvec(A, v):
    return [_dot(row, v) for row in A]


def _power(v, p):
    return [vi**p for vi in v]


def _times(u, v):
    return [ui * vi for ui, vi in zip(u, v, strict=True)]


ORDER_CONDITIONS = (
    (1, "sum b_i = 1", lambda A, b, c: sum(b, Fraction(0)), Fraction(1)),
    (2, "sum b_i c_i = 1/2", lambda A, b, c: _dot(b, c), Fraction(1, 2)),
    (3, "sum b_i c_i^2 = 1/3", lambda A, b, c: _dot(b, _power(c, 2)), Fraction(1, 3)),
    (3, "sum b_i a_ij c_j = 1/6", lambda A, b, c: _dot(b, _matvec(A, c)), Fraction(1, 6)),
    (4, "sum b_i c_i^3 = 1/4", lambda A, b, c: _dot(b, _power(c, 3)), Fraction(1, 4)),
    (4, "sum b_i c_i a_ij c_j = 1/8",
     lambda A, b, c: _dot(_times(b, c), _matvec(A, c)), Fraction(1, 8)),
    (4, "sum b_i a_ij c_j^2 = 1/12",
     lambda A, b, c: _dot(b, _matvec(A, _power(c, 2))), Fraction(1, 12)),
    (4, "sum b_i a_ij a_jk c_k = 1/24",
     lambda A, b, c: _dot(b, _matvec(A, _matvec(A, c))), Fraction(1, 24)),
)


def _fractions(rows):
    return tuple(tuple(Fraction(x) for x in row) for row in rows)


@dataclass(frozen=True)
class ExplicitRungeKutta:
    """An explicit Runge-Kutta method: its Butcher tableau and what it claims.

    Parameters
    ----------
    name : str
        The key in :data:`refsim.SOLVERS`, e.g. ``"rk4"``.
    A : sequence of sequences
        (s, s) strictly lower triangular coefficients ``a_ij``; entries are
        anything :class:`fractions.Fraction` accepts (ints, ``"1/2"``).
    b : sequence
        (s,) weights ``b_i``.
    c : sequence
        (s,) nodes ``c_i``: stage ``i`` is evaluated at ``t + c_i h``.
    seed_text : str
        The seed's sentence that defines the method, quoted.
    seed_order : int or None
        The global error order the seed states for it (claim C10), or None.
    title : str
        The method's name in the literature.

    Attributes
    ----------
    stages : int
        ``s``, the evaluations of ``f`` per step.
    order : int
        The order derived from the tableau (:meth:`derived_order`), 0 for an
        inconsistent method.
    A_, b_, c_ : numpy.ndarray
        The tableau as float64 arrays, shapes (s, s), (s,), (s,).
    """

    name: str
    A: tuple
    b: tuple
    c: tuple
    seed_text: str = ""
    seed_order: int | None = None
    title: str = ""
    A_: np.ndarray = field(init=False, repr=False, compare=False)
    b_: np.ndarray = field(init=False, repr=False, compare=False)
    c_: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        A = _fractions(self.A)
        (b,) = _fractions([self.b])
        (c,) = _fractions([self.c])
        s = len(b)
        if len(c) != s or len(A) != s or any(len(row) != s for row in A):
            raise ValueError(f"{self.name}: tableau shapes do not agree")
        if any(A[i][j] != 0 for i in range(s) for j in range(i, s)):
            raise ValueError(f"{self.name}: A is not strictly lower triangular")
        object.__setattr__(self, "A", A)
        object.__setattr__(self, "b", b)
        object.__setattr__(self, "c", c)
        for attr, value in (("A_", A), ("b_", b), ("c_", c)):
            array = np.array(value, dtype=np.float64)
            array.setflags(write=False)
            object.__setattr__(self, attr, array)

    @property
    def stages(self) -> int:
        return len(self.b)

    @property
    def order(self) -> int:
        return self.derived_order()

    def order_conditions(self) -> list[tuple[int, str, Fraction, Fraction]]:
        """Every order condition up to order 4 as ``(order, name, value,
        required)``, evaluated exactly. The conditions use ``c_i`` as given;
        :meth:`row_sums` says whether ``c_i = sum_j a_ij`` holds."""
        return [(p, name, value(self.A, self.b, self.c), want)
                for p, name, value, want in ORDER_CONDITIONS]

    def row_sums(self) -> tuple[Fraction, ...]:
        """``sum_j a_ij`` for each stage; equals ``c`` for a consistent tableau."""
        return tuple(sum(row, Fraction(0)) for row in self.A)

    def derived_order(self) -> int:
        """The largest ``p`` such that every condition of order ``<= p`` holds.

        0 means the method is not even consistent (``sum b != 1``). Exact
        because ``stages <= 4`` (see the module docstring); a method with more
        stages raises, since trees of order 5 and up are not checked here.
        """
        if self.stages > 4:
            raise NotImplementedError("order conditions are checked up to order 4 only")
        if self.row_sums() != self.c:
            # With c_i != sum_j a_ij, the method treats t and y differently and
            # the tree conditions above do not describe it.
            return 0
        order = 0
        for p in (1, 2, 3, 4):
            if all(value == want for q, _, value, want in self.order_conditions() if q == p):
                order = p
            else:
                break
        return order

    def step(self, f, t: float, y: np.ndarray, h: float) -> np.ndarray:
        """One step of size ``h`` from ``(t, y)``; see :func:`rk_step`."""
        return rk_step(self, f, t, y, h)


def rk_step(method: ExplicitRungeKutta, f, t: float, y: np.ndarray, h: float) -> np.ndarray:
    """One explicit Runge-Kutta step (HNW I, definition II.1.1).

    Parameters
    ----------
    method : ExplicitRungeKutta
    f : callable
        ``f(t, y) -> dy/dt``, with ``y`` and the result of shape (d,).
    t : float
    y : numpy.ndarray
        (d,) state at ``t``; not modified.
    h : float
        Step size.

    Returns
    -------
    numpy.ndarray
        (d,) state at ``t + h``. The sums are formed term by term in stage
        order, ``y + (h a_i1) k_1 + (h a_i2) k_2 + ...``, skipping zero
        coefficients, so that a method whose tableau is mostly zeros does
        exactly the arithmetic its seed sentence describes.
    """
    A, b, c = method.A_, method.b_, method.c_
    k = []
    for i in range(method.stages):
        y_i = y
        for j in range(i):
            if A[i, j] != 0.0:
                y_i = y_i + (h * A[i, j]) * k[j]
        k.append(np.asarray(f(t + c[i] * h, y_i)))
    y_next = y
    for i in range(method.stages):
        if b[i] != 0.0:
            y_next = y_next + (h * b[i]) * k[i]
    return y_next


def stages_with_own_state(method: ExplicitRungeKutta) -> list[bool]:
    """For each stage, whether it is evaluated at a state of its own (row i
    of A has a nonzero entry) rather than at ``y`` itself."""
    A = method.A_
    return [bool(A[i, :i].any()) for i in range(method.stages)]


def rk_step_into(method: ExplicitRungeKutta, f_into, t: float, Y: np.ndarray, h: float,
                 K: np.ndarray, stage: np.ndarray | None, scratch: np.ndarray) -> None:
    """:func:`rk_step` in place, into preallocated buffers: the same terms in
    the same order, so the same bits.

    Parameters
    ----------
    f_into : callable
        ``f_into(t, y, out)`` writes ``dy/dt`` into ``out`` (same shape as ``y``).
    Y : numpy.ndarray
        The state, any shape; overwritten with the state at ``t + h``.
    K : numpy.ndarray
        (s, *Y.shape) buffer for the stage derivatives ``k_i``.
    stage : numpy.ndarray or None
        Buffer of Y's shape for a stage state ``y_i``; None when no stage
        needs one (:func:`stages_with_own_state`).
    scratch : numpy.ndarray
        Buffer of Y's shape for the products ``(h a_ij) k_j``.

    The first term of a stage state is ``(h a_ij) k_j + Y``, which equals
    ``Y + (h a_ij) k_j`` to the bit (addition commutes exactly), without a
    copy of Y.
    """
    A, b, c = method.A_, method.b_, method.c_
    own = stages_with_own_state(method)
    for i in range(method.stages):
        if not own[i]:
            y_i = Y
        else:
            y_i = stage
            terms = [j for j in range(i) if A[i, j] != 0.0]
            np.multiply(K[terms[0]], h * A[i, terms[0]], out=y_i)
            np.add(y_i, Y, out=y_i)
            for j in terms[1:]:
                np.multiply(K[j], h * A[i, j], out=scratch)
                np.add(y_i, scratch, out=y_i)
        f_into(t + c[i] * h, y_i, K[i])
    for i in range(method.stages):
        if b[i] != 0.0:
            np.multiply(K[i], h * b[i], out=scratch)
            np.add(Y, scratch, out=Y)
