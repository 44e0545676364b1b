"""Measurements of the triangle-triangle test: filter fallback rate, agreement
with an oracle classified by cause, speed, and claim C4 (seed S4).

What: ``measure_*`` functions return frozen dataclasses of numbers that the
tests gate on and the report draws; nothing here prints or plots.

- :func:`measure_filter_fallback`: how often the float filter of the
  orientation predicates cannot decide and the exact fallback runs, on
  random and on near-degenerate input (Shewchuk 1997, section 4).
- :func:`compare_with_oracle` / :func:`classify_disagreement`: refsim's exact
  answers against another engine's (FCL, passed in as a callable so that
  refsim does not import the oracles), each disagreement labelled
  ``"coplanar"``, ``"touching"``, ``"tolerance"`` or ``"bug"``.
- :func:`measure_c4`: the seed's claim C4, "numerical issues do arise
  concerning intersecting nearly parallel edges and plains. This did not seem
  to be a problem in this simulation": a family of triangle pairs whose planes
  approach each other (angle theta = 1e-1 .. 1e-17), answered by refsim
  (exact), by the same test in plain floats, and by the oracle.
- :func:`measure_throughput`: pairs per second of the readable and the batch
  kernels (and the oracle, if given) on the same random pairs.

Cost: linear in the number of pairs; the classification runs the readable
kernel and O(1) extra exact predicates per disagreement.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from refsim.collision.disagreement import CLASSES, classify_triangle_pair
from refsim.collision.predicates import (
    orient2d_filtered,
    orient3d,
    orient3d_filtered,
    orient3d_terms,
)
from refsim.collision.triangle import triangles_intersect, triangles_intersect_float
from refsim.collision.triangle_batch import certified_batch, triangles_intersect_batch
from refsim.studies import TIMED
from refsim.types import random_rotation, rotation_about_axis, transform_points

TriangleTest = Callable[[np.ndarray, np.ndarray], bool]

#: How near-degenerate a pair is for :func:`measure_float_errors` (which
#: reports how near degeneracy the float tests go wrong; disagreements are
#: classified by their gap in metres, :func:`classify_disagreement`): some
#: orientation the decision depends on is this close to degenerate. The
#: measure is the normalized volume |det[a-d, b-d, c-d]| / (|a-d| |b-d| |c-d|)
#: (see :func:`decision_margin`): scale and translation invariant, in [0, 1],
#: roughly the distance of d from the plane abc over its distance from the
#: points, or the sine of the angle between nearly parallel edges. A float
#: engine whose arithmetic differs from ours (plane equations, projections,
#: clipping) errs by a few thousand ulps at most on such quantities, so 1e-12
#: (about 1e4 ulps of 1, the relative size of the classifier's rounding bound
#: :data:`refsim.collision.gaps.ROUNDING_ULPS`) covers any rounding.
NEAR_DEGENERATE_MARGIN = 1e-12

#: The classes of a disagreement (:func:`classify_disagreement`).
DISAGREEMENT_KINDS = CLASSES


# --------------------------------------------------------------------------
# filter fallback rate
# --------------------------------------------------------------------------

@dataclass(frozen=True)
class FallbackRates:
    """How often the float filter could not decide (fractions in [0, 1])."""

    n: int
    orient3d_random: float          # uniform points in [-1, 1]^3
    orient3d_near_plane: float      # d = a float point "on" plane abc (rounded)
    orient3d_integer_grid: float    # small-integer points, many exactly coplanar
    orient2d_random: float
    orient2d_near_line: float
    batch_random_pairs: float       # triangle pairs re-answered by the readable kernel
    batch_near_degenerate_pairs: float


def measure_filter_fallback(n: int = 20_000, seed: int = 0) -> FallbackRates:
    """Fallback rates of the filtered predicates and of the batch kernel."""
    rng = np.random.default_rng(seed)

    def rate3(points):
        return sum(not orient3d_filtered(*p)[1] for p in points.tolist()) / len(points)

    def rate2(points):
        return sum(not orient2d_filtered(*p)[1] for p in points.tolist()) / len(points)

    random3 = rng.uniform(-1.0, 1.0, (n, 4, 3))
    near = random3.copy()
    u, v = rng.uniform(0.0, 1.0, (2, n, 1))
    near[:, 3] = near[:, 0] + u * (near[:, 1] - near[:, 0]) + v * (near[:, 2] - near[:, 0])
    grid = rng.integers(-2, 3, (n, 4, 3)).astype(np.float64)
    random2 = rng.uniform(-1.0, 1.0, (n, 3, 2))
    near2 = random2.copy()
    near2[:, 2] = near2[:, 0] + u * (near2[:, 1] - near2[:, 0])

    A, B = rng.uniform(-1.0, 1.0, (2, n, 3, 3))
    _, certain = certified_batch(A, B)
    An, Bn, _ = near_degenerate_pairs(n, seed)
    _, certain_n = certified_batch(An, Bn)
    return FallbackRates(
        n=n,
        orient3d_random=rate3(random3), orient3d_near_plane=rate3(near),
        orient3d_integer_grid=rate3(grid),
        orient2d_random=rate2(random2), orient2d_near_line=rate2(near2),
        batch_random_pairs=float((~certain).mean()),
        batch_near_degenerate_pairs=float((~certain_n).mean()))


# --------------------------------------------------------------------------
# near-degenerate pairs
# --------------------------------------------------------------------------

NEAR_DEGENERATE_FAMILIES = ("vertex-on-face", "vertex-on-edge", "edge-crosses-edge",
                            "near-coplanar", "integer-grid")


def near_degenerate_pairs(n: int, seed: int = 0):
    """``(A, B, family)``: n triangle pairs built to touch up to rounding.

    Families (cycled): a vertex of B at a float point of A's face; on A's
    edge; an edge of B through a point of an edge of A; B in A's plane
    displaced along the normal by 1e-17 .. 1e-9; small-integer coordinates
    (exact touching and coplanarity are common). ``family`` is an array of
    indices into ``NEAR_DEGENERATE_FAMILIES``.
    """
    rng = np.random.default_rng(seed)
    A = rng.uniform(-1.0, 1.0, (n, 3, 3))
    B = rng.uniform(-1.0, 1.0, (n, 3, 3))
    family = np.arange(n) % len(NEAR_DEGENERATE_FAMILIES)
    u, v = rng.uniform(0.0, 1.0, (2, n, 1))
    sw = u + v > 1.0
    u[sw], v[sw] = 1.0 - u[sw], 1.0 - v[sw]
    e1 = A[:, 1] - A[:, 0]
    e2 = A[:, 2] - A[:, 0]
    on_face = A[:, 0] + u * e1 + v * e2
    on_edge = A[:, 0] + u * e1
    w = rng.standard_normal((n, 3))
    normal = np.cross(e1, e2)
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    offset = 10.0 ** rng.uniform(-17.0, -9.0, (n, 1)) * rng.choice([-1.0, 1.0], (n, 1))

    f = family == 0
    B[f, 0] = on_face[f]
    f = family == 1
    B[f, 0] = on_edge[f]
    f = family == 2
    B[f, 0] = on_edge[f] + w[f]
    B[f, 1] = on_edge[f] - rng.uniform(0.1, 2.0, (f.sum(), 1)) * w[f]
    f = family == 3
    for j in range(3):
        a_, b_ = rng.uniform(-0.5, 1.2, (2, n, 1))
        B[f, j] = (A[:, 0] + a_ * e1 + b_ * e2 + offset * normal)[f]
    f = family == 4
    A[f] = rng.integers(-2, 3, (f.sum(), 3, 3))
    B[f] = rng.integers(-2, 3, (f.sum(), 3, 3))
    return A, B, family


# --------------------------------------------------------------------------
# classification of disagreements with an oracle
# --------------------------------------------------------------------------

def decision_margin(t1, t2) -> float:
    """The smallest normalized volume of the orientations the decision uses.

    For orient3d(a, b, c, d) the normalized volume is
    |det[a-d, b-d, c-d]| / (|a-d| |b-d| |c-d|), in [0, 1] (Hadamard's
    inequality): 1 for three orthogonal directions, ~1e-16 for a point within
    rounding of a plane or edges within rounding of parallel, 0 for an exact
    zero. Used: the six vertex-versus-plane orientations, and the three line
    orientations of every edge whose endpoints are not strictly on one side.
    Evaluated in float64 (its rounding, ~1e-16, is far below the threshold it
    is compared with).
    """
    def rel(a, b, c, d):
        det, _ = orient3d_terms(a, b, c, d)
        lengths = math.prod(math.dist(p, d) for p in (a, b, c))
        return abs(det) / lengths if lengths > 0 else 0.0

    margins = []
    for e, t in ((t1, t2), (t2, t1)):
        a, b, c = t
        sides = [rel(a, b, c, p) for p in e]
        margins += sides
        for i in range(3):
            p, q = e[i], e[(i + 1) % 3]
            if orient3d(a, b, c, p) * orient3d(a, b, c, q) > 0:
                continue
            margins += [rel(p, q, a, b), rel(p, q, b, c), rel(p, q, c, a)]
    return min(margins)


def classify_disagreement(a, b) -> str:
    """Why an engine's answer may differ from refsim's exact one on (a, b):
    the class of :func:`refsim.collision.disagreement.classify_triangle_pair`
    (the conformance kit's too) for an engine that declares no tolerance:
    "coplanar" and "touching" by exact predicates, "bug" where refsim's
    answer differs from the rational ground truth, else "tolerance" when the
    pair's gap is within the float64 rounding bound and "bug" beyond it.

    Call it only for pairs where the answers differ; it does not look at
    them.
    """
    return classify_triangle_pair(a, b).kind


@dataclass(frozen=True)
class Disagreement:
    index: int
    refsim: bool
    oracle: bool
    kind: str
    gap: float              # metres: distance apart, minus the depth of a crossing
    bound: float            # the rounding bound the gap was compared with, metres


@dataclass(frozen=True)
class Agreement:
    """refsim against an oracle on n pairs."""

    n: int
    agree: int
    refsim_true: int
    oracle_true: int
    counts: dict = field(default_factory=dict)        # kind -> number of disagreements
    disagreements: tuple = ()                         # every Disagreement, in order

    def examples(self, kind: str, limit: int = 3) -> list[int]:
        return [d.index for d in self.disagreements if d.kind == kind][:limit]


def compare_with_oracle(A, B, oracle: TriangleTest) -> Agreement:
    """refsim (exact, batch kernel) against ``oracle(a, b) -> bool`` on pairs
    ``A[i], B[i]`` (k, 3, 3); every disagreement classified."""
    A = np.asarray(A, np.float64)
    B = np.asarray(B, np.float64)
    ours = triangles_intersect_batch(A, B)
    theirs = np.array([bool(oracle(a, b)) for a, b in zip(A, B, strict=True)], dtype=bool)
    found = []
    for i in np.flatnonzero(ours != theirs):
        verdict = classify_triangle_pair(A[i], B[i])
        found.append(Disagreement(int(i), bool(ours[i]), bool(theirs[i]), verdict.kind,
                                  verdict.gap, verdict.bound))
    counts = {kind: sum(d.kind == kind for d in found) for kind in DISAGREEMENT_KINDS}
    return Agreement(n=len(A), agree=int((ours == theirs).sum()), refsim_true=int(ours.sum()),
                     oracle_true=int(theirs.sum()), counts=counts, disagreements=tuple(found))


# --------------------------------------------------------------------------
# claim C4: near-parallel planes
# --------------------------------------------------------------------------

#: The angles of the C4 family: 1e-1 down to 1e-17 radians (below 2**-53 the
#: rotation's cosine rounds to 1 and the sine carries the whole tilt).
C4_THETAS = tuple(10.0 ** -e for e in range(1, 18))

#: Triangle A of the C4 family, in its local frame (in the plane z = 0).
C4_A = ((0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0))

#: B before the tilt, in A's plane, and the hinge line y = y0, z = 0 (along x)
#: it is tilted about. The intended answer holds for every theta > 0:
#: "overlap": B straddles a hinge that crosses A's interior -> True;
#: "touch": B's edge lies on the hinge inside A, B on one side -> True (touching);
#: "miss": the hinge runs outside A (y0 < 0) and B tilts up over A -> False,
#:         separated by about 0.05 * theta;
#: "shared-edge": B is hinged on A's edge (0,0,0)-(1,0,0), which it shares
#:         vertex for vertex, and tilts up over A -> True (touching along the
#:         edge), the case of two adjacent faces of a mesh folding flat.
C4_CONFIGS = {
    "overlap": (0.25, ((0.1, 0.05, 0.0), (0.6, 0.05, 0.0), (0.3, 0.45, 0.0)), True),
    "touch": (0.25, ((0.2, 0.25, 0.0), (0.5, 0.25, 0.0), (0.3, 0.6, 0.0)), True),
    "miss": (-0.05, ((0.2, -0.05, 0.0), (0.5, -0.05, 0.0), (0.3, 0.3, 0.0)), False),
    "shared-edge": (0.0, ((0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.3, 0.6, 0.0)), True),
}


@dataclass(frozen=True)
class C4Series:
    """One configuration in one frame, answered at every theta."""

    config: str
    frame: str                 # "axis-aligned" (A in z = 0) or "generic" (rigid motion)
    intended: bool             # the answer of the configuration before rounding
    thetas: tuple
    exact: tuple               # refsim on the float coordinates (exact for them)
    plain_float: tuple         # the same test with unfiltered float signs
    oracle: tuple              # the oracle (FCL), or () if none given
    # The largest theta, scanning down from 1e-1, where each answer first
    # differs from the intended one (None: never within the family).
    flip_exact: float | None
    flip_float: float | None
    flip_oracle: float | None
    # Thetas at which each float answer differs from the exact answer on the
    # same coordinates (an error of the method, not of rounding the input).
    float_wrong: int
    oracle_wrong: int


@dataclass(frozen=True)
class C4Result:
    series: tuple                                   # every C4Series

    def get(self, config: str, frame: str) -> C4Series:
        for s in self.series:
            if s.config == config and s.frame == frame:
                return s
        raise KeyError((config, frame))


def c4_pair(config: str, theta: float, frame: str = "generic", seed: int = 0):
    """The C4 triangle pair (A, B), two (3, 3) arrays, for one angle.

    ``frame="generic"`` applies one rigid motion (a seeded random rotation
    and a translation) to both triangles, so A is no longer axis-aligned and
    every coordinate is rounded; ``"axis-aligned"`` leaves A in z = 0.
    """
    y0, b_local, _ = C4_CONFIGS[config]
    hinge = np.array([0.0, y0, 0.0])
    tilt = rotation_about_axis([1.0, 0.0, 0.0], theta)
    A = np.array(C4_A)
    B = transform_points(np.array(b_local) - hinge, (tilt, hinge))
    if frame == "generic":
        rotation = random_rotation(np.random.default_rng(seed))
        translation = np.array([0.3, -0.7, 1.1])
        A = transform_points(A, (rotation, translation))
        B = transform_points(B, (rotation, translation))
    elif frame != "axis-aligned":
        raise ValueError(f"unknown frame {frame!r}")
    return A, B


def _first_flip(thetas, answers, intended):
    for theta, answer in zip(thetas, answers, strict=True):
        if answer != intended:
            return theta
    return None


def measure_c4(oracle: TriangleTest | None = None, seed: int = 0) -> C4Result:
    """Claim C4: where does each method's answer flip as planes go parallel?"""
    series = []
    for frame in ("axis-aligned", "generic"):
        for config, (_, _, intended) in C4_CONFIGS.items():
            exact, plain, theirs = [], [], []
            for theta in C4_THETAS:
                A, B = c4_pair(config, theta, frame, seed)
                exact.append(triangles_intersect(A, B))
                plain.append(triangles_intersect_float(A, B))
                if oracle is not None:
                    theirs.append(bool(oracle(A, B)))
            series.append(C4Series(
                config=config, frame=frame, intended=intended, thetas=C4_THETAS,
                exact=tuple(exact), plain_float=tuple(plain), oracle=tuple(theirs),
                flip_exact=_first_flip(C4_THETAS, exact, intended),
                flip_float=_first_flip(C4_THETAS, plain, intended),
                flip_oracle=_first_flip(C4_THETAS, theirs, intended) if theirs else None,
                float_wrong=sum(p != e for p, e in zip(plain, exact, strict=True)),
                oracle_wrong=sum(o != e for o, e in zip(theirs, exact, strict=False))))
    return C4Result(series=tuple(series))


@dataclass(frozen=True)
class C4Sweep:
    """The C4 family under many random rigid motions: per configuration and
    angle, how often the exact answer is True and how often the float test
    and the oracle differ from the exact answer on the same coordinates."""

    frames: int
    thetas: tuple
    configs: tuple
    exact_true: dict        # config -> tuple over thetas of counts (of frames)
    float_wrong: dict       # config -> tuple over thetas of counts
    oracle_wrong: dict      # config -> tuple over thetas of counts ({} without oracle)


def measure_c4_sweep(frames: int = 50, oracle: TriangleTest | None = None,
                     seed: int = 0) -> C4Sweep:
    """:func:`measure_c4` in ``frames`` seeded generic frames per angle."""
    exact_true, float_wrong, oracle_wrong = {}, {}, {}
    for config in C4_CONFIGS:
        e_counts, f_counts, o_counts = [], [], []
        for theta in C4_THETAS:
            e = f = o = 0
            for frame_seed in range(seed, seed + frames):
                A, B = c4_pair(config, theta, "generic", frame_seed)
                exact = triangles_intersect(A, B)
                e += exact
                f += triangles_intersect_float(A, B) != exact
                if oracle is not None:
                    o += bool(oracle(A, B)) != exact
            e_counts.append(e)
            f_counts.append(f)
            o_counts.append(o)
        exact_true[config] = tuple(e_counts)
        float_wrong[config] = tuple(f_counts)
        if oracle is not None:
            oracle_wrong[config] = tuple(o_counts)
    return C4Sweep(frames=frames, thetas=C4_THETAS, configs=tuple(C4_CONFIGS),
                   exact_true=exact_true, float_wrong=float_wrong, oracle_wrong=oracle_wrong)


@dataclass(frozen=True)
class FloatErrors:
    """Wrong answers of float tests, against refsim's exact answer, on
    :func:`near_degenerate_pairs` (per family) and on uniform random pairs."""

    n: int
    families: tuple                  # NEAR_DEGENERATE_FAMILIES
    plain_float_wrong: tuple         # per family
    oracle_wrong: tuple              # per family (empty without an oracle)
    random_plain_float_wrong: int
    random_oracle_wrong: int | None
    largest_margin_wrong: float      # largest decision_margin among all wrong answers


def measure_float_errors(n: int = 5000, seed: int = 0,
                         oracle: TriangleTest | None = None) -> FloatErrors:
    """How often plain-float signs (and the oracle) give a wrong answer."""
    A, B, family = near_degenerate_pairs(n, seed)
    exact = triangles_intersect_batch(A, B)
    plain = np.array([triangles_intersect_float(a, b) for a, b in zip(A, B, strict=True)])
    wrong = plain != exact
    theirs = None
    if oracle is not None:
        theirs = np.array([bool(oracle(a, b)) for a, b in zip(A, B, strict=True)])
    rng = np.random.default_rng(seed + 1)
    R1, R2 = rng.uniform(-1.0, 1.0, (2, n, 3, 3))
    exact_r = triangles_intersect_batch(R1, R2)
    plain_r = np.array([triangles_intersect_float(a, b) for a, b in zip(R1, R2, strict=True)])
    oracle_r = None
    if oracle is not None:
        oracle_r = int(sum(bool(oracle(a, b)) != e for a, b, e in zip(R1, R2, exact_r,
                                                                      strict=True)))
    any_wrong = wrong | (theirs != exact if theirs is not None else False)
    margins = [decision_margin(tuple(map(tuple, A[i].tolist())), tuple(map(tuple, B[i].tolist())))
               for i in np.flatnonzero(any_wrong)]
    fams = range(len(NEAR_DEGENERATE_FAMILIES))
    return FloatErrors(
        n=n, families=NEAR_DEGENERATE_FAMILIES,
        plain_float_wrong=tuple(int(wrong[family == f].sum()) for f in fams),
        oracle_wrong=() if theirs is None else tuple(int((theirs != exact)[family == f].sum())
                                                     for f in fams),
        random_plain_float_wrong=int((plain_r != exact_r).sum()),
        random_oracle_wrong=oracle_r,
        largest_margin_wrong=max(margins, default=0.0))


# --------------------------------------------------------------------------
# speed
# --------------------------------------------------------------------------

@dataclass(frozen=True)
class Throughput:
    """Pairs per second on the same random pairs (higher is faster)."""

    n: int
    readable: float = field(metadata=TIMED)
    batch: float = field(metadata=TIMED)
    oracle: float | None = field(metadata=TIMED)
    batch_fallback_fraction: float
    numba: float | None = field(default=None, metadata=TIMED)  # None when numba is not installed
    # Compiling the kernel from nothing (fresh interpreter, empty numba cache).
    numba_compile_seconds: float | None = field(default=None, metadata=TIMED)


def measure_throughput(n: int = 20_000, seed: int = 0,
                       oracle: TriangleTest | None = None, *,
                       cold_compile: bool = True) -> Throughput:
    """Readable vs batch kernel (vs the numba kernel and the oracle, when
    available) on n uniform random pairs.

    The readable kernel and the oracle run on the first min(n, 5000) pairs
    only, to bound the time; the rates are per pair either way. The numba
    rate excludes compilation, which is reported separately: compiled from
    nothing in a fresh interpreter (tens of seconds), unless
    ``cold_compile`` is False (``numba_compile_seconds`` is then None).
    """
    rng = np.random.default_rng(seed)
    A, B = rng.uniform(-1.0, 1.0, (2, n, 3, 3))
    m = min(n, 5000)
    start = time.perf_counter()
    ours = triangles_intersect_batch(A, B)
    batch = n / (time.perf_counter() - start)
    start = time.perf_counter()
    readable_answers = [triangles_intersect(a, b) for a, b in zip(A[:m], B[:m], strict=True)]
    readable = m / (time.perf_counter() - start)
    if list(ours[:m]) != readable_answers:
        raise AssertionError("batch and readable kernels disagree")
    oracle_rate = None
    if oracle is not None:
        start = time.perf_counter()
        for a, b in zip(A[:m], B[:m], strict=True):
            oracle(a, b)
        oracle_rate = m / (time.perf_counter() - start)
    numba_rate = compile_seconds = None
    from refsim.collision import triangle_numba
    if triangle_numba.available():
        # Compilation from nothing, measured in a fresh interpreter.
        if cold_compile:
            compile_seconds = triangle_numba.measure_numba_compile_seconds()
        triangle_numba.triangles_intersect_numba(A[:1], B[:1])   # compile here first
        start = time.perf_counter()
        fast = triangle_numba.triangles_intersect_numba(A, B)
        numba_rate = n / (time.perf_counter() - start)
        if not np.array_equal(fast, ours):
            raise AssertionError("numba and batch kernels disagree")
    _, certain = certified_batch(A, B)
    return Throughput(n=n, readable=readable, batch=batch, oracle=oracle_rate,
                      batch_fallback_fraction=float((~certain).mean()),
                      numba=numba_rate, numba_compile_seconds=compile_seconds)
