"""One way to write a case generator, two sources of randomness.

Each generated case family (triangle pairs, mesh poses, boxes) is written
once, as a *builder*: a function of a :class:`Draw` that asks for the
numbers it needs (``uniform``, ``integers``, ``choice``) and returns the
case. The seeded case set runs the builder on :class:`NumpyDraw` (a
``numpy.random.Generator``: fast, the same cases for the same seed on every
machine); a failure is then searched for again, and shrunk, by Hypothesis
running the same builder on :class:`HypothesisDraw` (each number a
Hypothesis strategy, so shrinking simplifies the builder's parameters: the
minimal failing input is a member of the same family, as the Array API test
suite shows a minimal array).

Reference: D. R. MacIver, Z. Hatfield-Dodds et al., "Hypothesis: A new
approach to property-based testing", JOSS 4(43), 2019 (shrinking of the
choices a test draws, not of its output).

Cost: O(1) per number drawn.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence
from typing import Any, NoReturn, Protocol

import numpy as np


class Draw(Protocol):
    """What a builder asks of its source of numbers: :class:`NumpyDraw` or
    :class:`HypothesisDraw`."""

    #: How many times a builder may draw again after an unusable case.
    retries: int

    def reject(self) -> NoReturn:
        """Give up on this case: every draw made an unusable one."""
        ...

    def uniform(self, lo: float, hi: float, n: int = 1) -> list[float]: ...

    def integers(self, lo: int, hi: int, n: int = 1) -> list[int]: ...

    def choice(self, options: Sequence[Any]) -> Any: ...

    def log_uniform(self, lo_exp: float, hi_exp: float) -> float: ...


class NumpyDraw:
    """Numbers from a seeded ``numpy.random.Generator``.

    A builder that made an unusable case (a degenerate triangle) draws again
    up to ``retries`` times: fresh numbers come each time.
    """

    retries = 200

    def __init__(self, rng: np.random.Generator):
        self.rng = rng

    def reject(self) -> NoReturn:
        raise RuntimeError("a case builder made only unusable cases: a bug in the builder")

    def uniform(self, lo: float, hi: float, n: int = 1) -> list[float]:
        return [float(x) for x in self.rng.uniform(lo, hi, n)]

    def integers(self, lo: int, hi: int, n: int = 1) -> list[int]:
        """``n`` integers in ``[lo, hi]`` (both ends included)."""
        return [int(x) for x in self.rng.integers(lo, hi + 1, n)]

    def choice(self, options):
        return options[int(self.rng.integers(0, len(options)))]

    def log_uniform(self, lo_exp: float, hi_exp: float) -> float:
        """``10**x`` for ``x`` uniform in ``[lo_exp, hi_exp]``."""
        return float(10.0 ** self.rng.uniform(lo_exp, hi_exp))


class HypothesisDraw:
    """Numbers from Hypothesis strategies (``draw`` of ``st.composite`` or
    ``st.data()``), so that Hypothesis can shrink them."""

    #: Drawing again would repeat a shrunk draw: an unusable case is
    #: rejected instead (Hypothesis then tries other values).
    retries = 1

    def __init__(self, draw):
        self.draw = draw

    def reject(self) -> NoReturn:
        from hypothesis import reject

        reject()

    def uniform(self, lo: float, hi: float, n: int = 1) -> list[float]:
        from hypothesis import strategies as st

        s = st.floats(lo, hi, allow_nan=False, allow_infinity=False)
        return [float(self.draw(s)) for _ in range(n)]

    def integers(self, lo: int, hi: int, n: int = 1) -> list[int]:
        from hypothesis import strategies as st

        return [int(self.draw(st.integers(lo, hi))) for _ in range(n)]

    def choice(self, options):
        from hypothesis import strategies as st

        return self.draw(st.sampled_from(list(options)))

    def log_uniform(self, lo_exp: float, hi_exp: float) -> float:
        # an integer exponent shrinks towards lo_exp: the most degenerate
        # end of the range is the simplest one to show
        from hypothesis import strategies as st

        return float(10.0 ** self.draw(st.integers(math.ceil(lo_exp), math.floor(hi_exp))))


def strategy(builder, *args):
    """The Hypothesis strategy of ``builder(draw, *args)``."""
    from hypothesis import strategies as st

    @st.composite
    def build(draw):
        return builder(HypothesisDraw(draw), *args)

    return build()


def dot3(u, v) -> float:
    """``u . v`` of two 3-vectors, summed left to right (no BLAS: the same
    bits on every machine, so a seed gives the same cases everywhere)."""
    return float((u[0] * v[0] + u[1] * v[1]) + u[2] * v[2])


def matmul3(a, b) -> np.ndarray:
    """The (3, 3) product ``a b``, each entry by :func:`dot3` (no BLAS)."""
    return np.array([[dot3(a[i], b[:, j]) for j in range(3)] for i in range(3)])


def unit_quaternion_rotation(draw) -> np.ndarray:
    """A rotation from four drawn numbers (normalized as a quaternion;
    the identity when all four are 0, which is where Hypothesis shrinks)."""
    from refsim.types import quaternion_to_rotation

    q = np.array(draw.uniform(-1.0, 1.0, 4))
    norm = math.sqrt(float(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]))
    if norm < 1e-3:
        return np.eye(3)
    return quaternion_to_rotation(q / norm)


@functools.cache
def signed_permutations() -> tuple[np.ndarray, ...]:
    """The 24 proper rotations with entries in {-1, 0, 1}: a point's
    rotated coordinates are exact (each is +-1 times one coordinate).
    Built once (read-only arrays)."""
    from itertools import permutations, product

    out = []
    for perm in permutations(range(3)):
        inversions = sum(perm[i] > perm[j] for i in range(3) for j in range(i + 1, 3))
        for signs in product((1.0, -1.0), repeat=3):
            # det = sign of the permutation times the product of the signs
            if (-1) ** inversions * signs[0] * signs[1] * signs[2] != 1:
                continue
            m = np.zeros((3, 3))
            for row, col in enumerate(perm):
                m[row, col] = signs[row]
            m.flags.writeable = False
            out.append(m)
    return tuple(out)


#: Cases of a seeded set drawn from one random stream. Case ``i`` comes from
#: stream ``i // BLOCK`` (:func:`seeded_range`), so any run of whole blocks
#: is built alone, by a shard on another process, and a set is the same
#: however it is split. A multiple of every family count (4 and 6), so that
#: the families cycle the same way in every block.
BLOCK = 12_000


def block_draw(seed: int, tag: int, block: int) -> NumpyDraw:
    """The draw of block ``block`` of the set tagged ``tag``. Block 0 keeps
    the stream every set was drawn from before sets came in blocks, so that
    a set of up to :data:`BLOCK` cases is the one it always was."""
    key = [seed, tag] if block == 0 else [seed, tag, block]
    return NumpyDraw(np.random.default_rng(key))


def seeded_range(build, seed: int, tag: int, start: int, stop: int) -> tuple:
    """Cases ``start`` to ``stop - 1`` of a seeded set, ``build(draw, i)``
    making case ``i``. A range that starts inside a block draws (and drops)
    the block's earlier cases: give whole blocks to avoid that cost."""
    out = []
    for block in range(start // BLOCK, -(-stop // BLOCK)):
        draw = block_draw(seed, tag, block)
        for i in range(block * BLOCK, min(stop, (block + 1) * BLOCK)):
            case = build(draw, i)
            if i >= start:
                out.append(case)
    return tuple(out)
