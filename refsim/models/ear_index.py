"""Ear clipping with an index of the corners that can block an ear (seed S1).

:func:`clip_ears` clips the same ears in the same order as the
specification, :func:`refsim.models.triangulate.ear_clip_reference`
(Eberly, "Triangulation by Ear Clipping", Geometric Tools, 2002; O'Rourke,
*Computational Geometry in C*, 2nd ed., sec. 1.6), and so returns the same
triangles, bit for bit. The specification tests each candidate ear against
every other corner of the ring and walks the ring to find the next ear,
O(k^2) for ``k`` corners. Here the same float ear test is asked of fewer
corners, found through a tree, and the next ear comes from a queue. Input:
the projected corners ``xs, ys`` (k,) of
:func:`refsim.models.triangulate.project_polygon` (counter-clockwise, every
coordinate in (-1, 1)).

1. Which corners can block an ear. The specification's test: corner ``i``
   with neighbours ``a``, ``b`` is an ear when it is strictly convex and no
   other remaining corner ``j`` lies in the closed triangle ``T = (a, i, b)``
   without coinciding with one of its three corners; call such ``j``
   *blockers*. Eberly (sec. 2) observes that only reflex corners need be
   tested. With a closed triangle and the coincidence rule that needs care;
   what holds is (exact arithmetic, simple polygon):

   *Lemma.* If ``T`` has a blocker, then it has a reflex blocker
   (``orient(prev, j, next) < 0``), or the corner after ``b`` is a blocker.

   *Proof.* Measure heights above the line ``ab`` towards ``i``; let ``x`` be
   a highest blocker. (i) ``h(x) > 0``: the part of ``T`` above ``h(x)``
   holds no corner and no edge (an edge could only enter it by crossing
   ``ai`` or ``ib``), so it is interior, as it is near ``i``. Both
   neighbours of ``x`` lie at most at ``h(x)`` (a higher one would be a
   blocker, or beyond ``ai``/``ib``). Interior above, boundary below: ``x``
   is reflex, or straight with both neighbours at ``h(x)``; they are then
   blockers too, and that straight run ends inside ``T`` at a blocker that
   turns down, a reflex one. (ii) ``h(x) = 0``: all blockers lie on the
   segment ``ab``, and the part of ``T`` above it is interior, as in (i). So,
   as in (i), each blocker is reflex or straight with both neighbours on the
   line ``ab``. A straight run along ``ab`` cannot leave the segment without
   passing through ``a`` or ``b`` (not simple), so it ends at a reflex
   blocker, or at ``a`` and ``b`` themselves; the run then, traversed ``b``
   to ``a`` (the interior on its left), is the whole chain from ``b`` to
   ``a``, and the corner after ``b`` is on it. QED.

   So the *candidates* are the reflex corners, and the corner after ``b`` is
   tested by name. Straight corners (collinear runs) and convex ones are
   never candidates, except where the proof's premises fail:

   * a corner whose turn is zero without going straight on (a spike that
     turns back, a zero-length edge), or positive but within Shewchuk's
     rounding error (:func:`orient_error`: it may be reflex);
   * *contacts*: a corner whose point the polygon visits more than once (a
     bridge to a hole, a spike, a repeated point), a corner that lies on
     another edge short of its ends (overlapping spikes, collinear points on
     a spike; within the rounding error), and the two ends of that edge
     (:func:`mark_contacts`, once, on the input polygon: a diagonal the
     clipping adds passes through no corner but at its ends, or the ear
     that made it would have been blocked); and each ring neighbour of a
     contact. These are where "no edge enters the part above ``x``" and "no
     neighbour higher than ``x``" fail: a second visit of ``i``'s point, or
     an edge touching ``ai``, ``ib`` or the point ``i``, whose ends are then
     the blockers.

   A corner's candidacy depends on its turn and its neighbours, which change
   only for the two neighbours of a clipped ear; after each clip those two
   are re-examined, nothing else.

   DEVIATION (outside the contract): on self-intersecting polygons, and on
   polygons the specification itself turns self-intersecting (two lobes
   pinched at one point: its coincidence rule can let a diagonal pass the
   other visit of a corner on the wrong side, and its output then has a
   triangle of the wrong winding), and where float rounding alone decides
   whether a corner within a few ulps of a diagonal blocks, the clipping can
   differ from the specification's. It still returns ``k - 2`` triangles of
   the polygon's corners and terminates (the same fallback).

2. The index. A k-d tree over all ``k`` corners (Bentley, "Multidimensional
   binary search trees used for associative searching", CACM 18(9), 1975;
   split at the median of the longer side, ``LEAF_SIZE`` corners a leaf)
   keeps, per node, the box of its corners and the number of candidates
   below it. An ear test descends only into nodes holding a candidate whose
   box can meet ``T``, and runs the specification's float test on each
   candidate in the leaves it reaches. Pruning never drops a corner the
   float test would accept:

   * by an edge ``p -> q`` of ``T``: the specification computes
     ``orient(p, q, j) = (x_q - x_p)(y_j - y_p) - (y_q - y_p)(x_j - x_p)``
     in floats, and rounding is monotone, so over a box that expression is
     largest, as computed, at the corner picked by the signs of
     ``x_q - x_p`` and ``y_q - y_p`` (:func:`box_outside_edge`). Negative
     there: negative, as computed, for every corner in the box.
   * by ``T``'s bounding box, widened: rounding lets the float test accept
     points slightly outside ``T``. Shewchuk's bound ("Adaptive precision
     floating-point arithmetic and fast robust geometric predicates", 1997,
     sec. 4.3: error <= (3 + 16u) u (|x_q - x_p||y_j - y_p| +
     |y_q - y_p||x_j - x_p|), u = 2^-53) says an accepted ``j`` has
     ``orient(p, q, j) >= -s |q - p| |j - p|`` exactly for each edge, with
     ``s = ACCEPT_SLOPE``. So ``j`` lies in ``T`` grown by ``s |j - p|`` on
     each side; with ``sin(theta/2) >= C / (2 L^2)`` for the smallest angle
     (``C = orient(a, i, b)``, ``L`` the longest edge's ``|dx| + |dy|``) it
     lies within ``2 s L^3 / (C - 2 s L^2)`` of ``T`` (a margin that also
     absorbs the rounding of ``C``). When ``C <= 2 s L^2`` the triangle is
     degenerate up to rounding and only the edge tests prune. (Both bounds
     assume no product underflows: corners closer than about 1e-150 of the
     polygon's size.)

3. The next ear. The specification walks the ring from the last clip's
   successor to the first corner flagged as an ear, after recomputing the
   flags of only the two neighbours of each clipped ear (a flag that turns
   true later stays false until then; recomputing the same flags at the
   same moments reproduces that). The walk visits corners in index order
   from the pointer, wrapping once; so a corner ``x`` is at *walk position*
   ``P + (x - p) mod k`` for the pointer ``p`` at position ``P``, and
   positions only grow. A heap of the positions of flagged corners gives
   the walk's answer: the smallest position not behind the pointer whose
   corner is still flagged (stale entries are dropped when they surface).
   When there is none, the specification's fallback clips the corner with
   the largest turn, the first in walk order on ties; a tournament tree over
   the turns (:func:`most_convex`) answers that in O(log k).

Cost: building the tree O(k log^2 k); each ear test O(log k + the nodes
near ``T`` holding candidates), a few dozen for typical polygons, so about
O(k log k) in all for a circle, a star, a comb, a spiral, collinear runs
(straight corners are not candidates; tilted runs, whose corners rounding
makes reflex or uncertain, are pruned by the widened box) and repeated
points; the tests count the work. Worse: polygons with nearly every corner
reflex whose ears are long slivers through them (a star with a random
radius at every corner: about O(k^1.5)), and polygons whose corners lie on
a line up to rounding, where the box cannot be trusted (a sliver of
thousands of corners along a tilted line: hundreds of point tests a corner);
the worst case is O(k^2). The loops are plain Python over arrays so that
numba compiles this same source (:mod:`refsim.models._numba_kernels`);
uncompiled it is the readable version the tests compare with.
"""

from __future__ import annotations

import heapq
from typing import NamedTuple

import numpy as np

from refsim.kernels import CORNER_TREE, EAR_CLIPPING, choose_kernel
from refsim.rounding import O2D_ERRBOUND_A

#: Corners per leaf of the k-d tree. Smaller leaves prune closer to the
#: triangle but cost more nodes per query; on the 100 000-corner benchmark
#: polygons, leaves of 2 to 16 corners were within the timing noise.
LEAF_SIZE = 8

#: Slope of the float test's reach: a point ``j`` it accepts has
#: ``orient(p, q, j) >= -ACCEPT_SLOPE |q - p| |j - p|`` exactly, for each edge
#: ``p -> q``: Shewchuk's bound with Cauchy-Schwarz gives 3u (1 + O(u)); 8u
#: leaves room for the rounding of ``C`` and of the margin (module docstring, 2).
ACCEPT_SLOPE = 8.0 * 2.0**-53

#: Indices into the ``work`` counters of :func:`clip_ears`.
EAR_TESTS, POINT_TESTS, NODE_VISITS, FALLBACKS = 0, 1, 2, 3

#: Depth bound of the tree's descent stack: the tree is balanced, so its
#: depth is at most log2(k) + 1 < 64 for any k that fits in memory.
STACK_SIZE = 128


class CornerTree(NamedTuple):
    """A k-d tree over the projected corners, with candidate counts.

    Node ``n`` (the root is 0) holds the corners ``perm[first[n]:end[n]]``;
    an inner node's children are ``child[n]`` and ``child[n] + 1``, a leaf
    has ``child[n] == -1``. ``xmin .. ymax`` (m,) bound its corners;
    ``count`` (m,) is the number of them that are candidates now, updated as
    clipping goes on. ``leaf`` (k,) is the leaf holding each corner.
    """

    perm: np.ndarray
    leaf: np.ndarray
    first: np.ndarray
    end: np.ndarray
    child: np.ndarray
    parent: np.ndarray
    xmin: np.ndarray
    xmax: np.ndarray
    ymin: np.ndarray
    ymax: np.ndarray
    # The field shadows tuple.count, which a NamedTuple allows at run time; the
    # name is the one used by the compiled kernels and the tests.
    count: np.ndarray                             # type: ignore[assignment]


class Ring(NamedTuple):
    """The remaining polygon: a doubly linked ring over corner indices (k,).

    ``turn[v]`` is ``orient(prev[v], v, next[v])`` for the current neighbours,
    ``candidate[v]`` whether ``v`` may block an ear (step 1 of the module
    docstring), ``ear[v]`` the specification's ear flag as last computed.
    """

    prev: np.ndarray
    next: np.ndarray
    turn: np.ndarray
    candidate: np.ndarray
    ear: np.ndarray


def orient(xs, ys, a, b, c):
    """Twice the signed area of the 2-D triangle (a, b, c); > 0 when CCW.

    The specification's formula, operand for operand: the pruning in
    :func:`box_outside_edge` relies on the same rounding.
    """
    return (xs[b] - xs[a]) * (ys[c] - ys[a]) - (ys[b] - ys[a]) * (xs[c] - xs[a])


def blocks(xs, ys, a, i, b, j):
    """Whether corner ``j`` blocks the ear ``(a, i, b)``: it lies in the closed
    triangle and its point is none of the triangle's three corners."""
    x, y = xs[j], ys[j]
    if (x == xs[a] and y == ys[a]) or (x == xs[i] and y == ys[i]) or (x == xs[b] and y == ys[b]):
        return False
    return (orient(xs, ys, a, i, j) >= 0.0 and orient(xs, ys, i, b, j) >= 0.0
            and orient(xs, ys, b, a, j) >= 0.0)


def orient_error(xs, ys, a, b, c):
    """Shewchuk's bound on the rounding error of :func:`orient` as computed:
    if ``|orient(a, b, c)|`` is larger, its sign is the exact one."""
    return O2D_ERRBOUND_A * (abs((xs[b] - xs[a]) * (ys[c] - ys[a]))
                             + abs((ys[b] - ys[a]) * (xs[c] - xs[a])))


def is_candidate(xs, ys, marked, ring, v):
    """Whether corner ``v`` may block an ear (step 1 of the module docstring):
    reflex (or convex by less than the rounding error), turning by zero
    without going straight on, or next to a ``marked`` corner or marked
    itself ((k,) bool: a repeated point, or a touch, see :func:`mark_contacts`)."""
    a, b = ring.prev[v], ring.next[v]
    turn = ring.turn[v]
    if turn < 0.0:
        return True
    if turn == 0.0:
        ahead = (xs[v] - xs[a]) * (xs[b] - xs[v]) + (ys[v] - ys[a]) * (ys[b] - ys[v])
        if not ahead > 0.0:
            return True  # a spike that turns back, or a zero-length edge
    elif turn <= orient_error(xs, ys, a, v, b):
        return True  # convex only by rounding: may be reflex
    return marked[v] or marked[a] or marked[b]


def set_candidate(tree, ring, v, value):
    """Make ``v`` a candidate or not, keeping the counts up the tree."""
    ring.candidate[v] = value
    step = 1 if value else -1
    n = tree.leaf[v]
    while n >= 0:
        tree.count[n] += step
        n = tree.parent[n]


def box_outside_edge(xs, ys, tree, n, p, q, margin):
    """Whether every point ``j`` of node ``n``'s box has ``orient(p, q, j) <
    -margin`` as the specification computes it: the largest value over the
    box, at the corner the signs pick, is (module docstring, step 2)."""
    ex = xs[q] - xs[p]
    ey = ys[q] - ys[p]
    cx = tree.xmin[n] if ey > 0.0 else tree.xmax[n]
    cy = tree.ymax[n] if ex > 0.0 else tree.ymin[n]
    return ex * (cy - ys[p]) - ey * (cx - xs[p]) < -margin


def is_ear(xs, ys, tree, ring, stack, work, i):
    """The specification's ear test for corner ``i`` of the current ring,
    asked only of the candidates near the triangle and of the corner after
    ``b`` (the lemma's two cases). ``stack`` (STACK_SIZE,) is scratch."""
    work[EAR_TESTS] += 1
    a, b = ring.prev[i], ring.next[i]
    if not ring.turn[i] > 0.0:
        return False  # reflex or collinear: clipping it would fold the polygon
    after_b = ring.next[b]
    if after_b != a:
        work[POINT_TESTS] += 1
        if blocks(xs, ys, a, i, b, after_b):
            return False
    if tree.count[0] == 0:
        return True
    # T's box, widened by the reach of rounding (module docstring, step 2);
    # no box test when T is within rounding of degenerate.
    turn = ring.turn[i]
    longest = max(abs(xs[i] - xs[a]) + abs(ys[i] - ys[a]), abs(xs[b] - xs[i]) + abs(ys[b] - ys[i]),
                  abs(xs[a] - xs[b]) + abs(ys[a] - ys[b]))
    slack = 2.0 * ACCEPT_SLOPE * longest * longest
    use_box = turn > slack
    margin = slack * longest / (turn - slack) if use_box else 0.0
    x_lo = min(xs[a], xs[i], xs[b]) - margin
    x_hi = max(xs[a], xs[i], xs[b]) + margin
    y_lo = min(ys[a], ys[i], ys[b]) - margin
    y_hi = max(ys[a], ys[i], ys[b]) + margin
    top = 0
    stack[0] = 0
    while top >= 0:
        n = stack[top]
        top -= 1
        work[NODE_VISITS] += 1
        if tree.count[n] == 0:
            continue
        if use_box and (tree.xmin[n] > x_hi or tree.xmax[n] < x_lo or tree.ymin[n] > y_hi
                        or tree.ymax[n] < y_lo):
            continue
        if (box_outside_edge(xs, ys, tree, n, a, i, 0.0)
                or box_outside_edge(xs, ys, tree, n, i, b, 0.0)
                or box_outside_edge(xs, ys, tree, n, b, a, 0.0)):
            continue
        c = tree.child[n]
        if c >= 0:
            stack[top + 1] = c + 1
            stack[top + 2] = c
            top += 2
            continue
        for s in range(tree.first[n], tree.end[n]):
            j = tree.perm[s]
            if ring.candidate[j]:
                work[POINT_TESTS] += 1
                if blocks(xs, ys, a, i, b, j):
                    return False
    return True


def mark_contacts(xs, ys, tree, stack, work, marked):
    """Mark (in ``marked``, (k,) bool, which holds the repeated points on
    entry) the corners where the polygon may touch itself: each corner whose
    point lies on another edge short of its ends, within the rounding error
    of :func:`orient`, and the two ends of that edge. One segment query of
    the tree per edge (counted in ``work`` with the ear tests' nodes and
    point tests); the tree's candidate counts are not used."""
    k = len(xs)
    for p in range(k):
        q = (p + 1) % k
        x_lo, x_hi = min(xs[p], xs[q]), max(xs[p], xs[q])
        y_lo, y_hi = min(ys[p], ys[q]), max(ys[p], ys[q])
        # With |coordinates| < 1, orient_error(p, q, j) and the rounding of
        # orient(p, q, j) and of orient(q, p, j) are each below
        # 2 O2D_ERRBOUND_A (|dx| + |dy|): a box whose largest value of either,
        # as computed, is below -band holds no corner within orient_error of the line.
        band = 16.0 * O2D_ERRBOUND_A * (abs(xs[q] - xs[p]) + abs(ys[q] - ys[p]))
        top = 0
        stack[0] = 0
        while top >= 0:
            n = stack[top]
            top -= 1
            work[NODE_VISITS] += 1
            if (tree.xmin[n] > x_hi or tree.xmax[n] < x_lo or tree.ymin[n] > y_hi
                    or tree.ymax[n] < y_lo):
                continue
            if (box_outside_edge(xs, ys, tree, n, p, q, band)
                    or box_outside_edge(xs, ys, tree, n, q, p, band)):
                continue
            c = tree.child[n]
            if c >= 0:
                stack[top + 1] = c + 1
                stack[top + 2] = c
                top += 2
                continue
            for s in range(tree.first[n], tree.end[n]):
                j = tree.perm[s]
                work[POINT_TESTS] += 1
                x, y = xs[j], ys[j]
                if (x == xs[p] and y == ys[p]) or (x == xs[q] and y == ys[q]):
                    continue
                if (x_lo <= x <= x_hi and y_lo <= y <= y_hi
                        and abs(orient(xs, ys, p, q, j)) <= orient_error(xs, ys, p, q, j)):
                    marked[j] = True
                    marked[p] = True
                    marked[q] = True


def better(turn, u, v):
    """Of corners ``u`` and ``v`` (-1 for none), the one with the larger turn;
    ``u`` on ties (``u`` comes first in walk order)."""
    if v < 0:
        return u
    if u < 0:
        return v
    return u if turn[u] >= turn[v] else v


def tournament_set(turn, best, v, present):
    """Enter corner ``v`` in the tournament tree ``best`` (2 * size,) with its
    current turn, or take it out (``present`` False), replaying the matches
    up to the root. Leaf ``size + v`` holds ``v``; node ``n`` the winner of
    its children ``2n`` and ``2n + 1``."""
    size = len(best) // 2
    n = size + v
    best[n] = v if present else -1
    n //= 2
    while n >= 1:
        best[n] = better(turn, best[2 * n], best[2 * n + 1])
        n //= 2


def tournament_first_best(turn, best, lo, hi):
    """The corner of ``lo .. hi - 1`` with the largest turn, the first (lowest
    index) on ties, -1 if there is none: the standard bottom-up range query,
    keeping the left and the right partial winners apart so that order is kept."""
    size = len(best) // 2
    left, right = -1, -1
    lo += size
    hi += size
    while lo < hi:
        if lo & 1:
            left = better(turn, left, best[lo])
            lo += 1
        if hi & 1:
            hi -= 1
            right = better(turn, best[hi], right)
        lo //= 2
        hi //= 2
    return better(turn, left, right)


def most_convex(turn, best, start):
    """The specification's fallback: the remaining corner with the largest
    turn, the first one on ties walking the ring from ``start``; the walk
    covers ``start .. k - 1``, then ``0 .. start - 1``."""
    k = len(turn)
    return better(turn, tournament_first_best(turn, best, start, k),
                  tournament_first_best(turn, best, 0, start))


def build_tree(xs, ys, perm, leaf, first, end, child, parent, xmin, xmax, ymin, ymax,
               leaf_size):
    """Fill the arrays of a :class:`CornerTree` (each with room for ``2k``
    nodes) breadth first; returns the number of nodes. ``perm`` must hold
    ``0 .. k-1``. Each inner node sorts its corners along the longer side of
    its box and gives each child half."""
    k = len(xs)
    first[0], end[0], parent[0] = 0, k, -1
    m = 1
    n = 0
    while n < m:
        lo, hi = first[n], end[n]
        j = perm[lo]
        xmin[n], xmax[n], ymin[n], ymax[n] = xs[j], xs[j], ys[j], ys[j]
        for s in range(lo + 1, hi):
            j = perm[s]
            xmin[n] = min(xmin[n], xs[j])
            xmax[n] = max(xmax[n], xs[j])
            ymin[n] = min(ymin[n], ys[j])
            ymax[n] = max(ymax[n], ys[j])
        if hi - lo <= leaf_size:
            child[n] = -1
            for s in range(lo, hi):
                leaf[perm[s]] = n
        else:
            run = perm[lo:hi].copy()
            key = xs[run] if xmax[n] - xmin[n] >= ymax[n] - ymin[n] else ys[run]
            perm[lo:hi] = run[np.argsort(key, kind="mergesort")]
            middle = (lo + hi) // 2
            child[n] = m
            first[m], end[m], parent[m] = lo, middle, n
            first[m + 1], end[m + 1], parent[m + 1] = middle, hi, n
            m += 2
        n += 1
    return m


def clip_ears(xs, ys, marked, tree, ring, best, out, work):
    """Clip the projected polygon ``xs, ys`` (k,) into ``out`` (k - 2, 3).

    ``marked`` (k,) marks the corners whose point occurs more than once (the
    other contacts are added here, :func:`mark_contacts`); ``tree`` is built
    over ``xs, ys`` with zero counts; ``ring``'s arrays (k,) are filled here;
    ``best`` (2 size,), size a power of two >= k, is the fallback's
    tournament tree. ``work`` (4,) counts ear tests, point tests (in a
    triangle, on an edge), tree nodes visited and fallback clips (indices
    ``EAR_TESTS`` ..).
    """
    k = len(xs)
    for v in range(k):
        ring.prev[v] = (v - 1) % k
        ring.next[v] = (v + 1) % k
    for v in range(k):
        ring.turn[v] = orient(xs, ys, ring.prev[v], v, ring.next[v])
        ring.candidate[v] = False
    stack = np.empty(STACK_SIZE, np.int64)
    mark_contacts(xs, ys, tree, stack, work, marked)
    for v in range(k):
        if is_candidate(xs, ys, marked, ring, v):
            set_candidate(tree, ring, v, True)
    for v in range(k):
        ring.ear[v] = is_ear(xs, ys, tree, ring, stack, work, v)
    best[:] = -1
    for v in range(k):
        tournament_set(ring.turn, best, v, True)

    # The walk starts at corner 1 (position 1); see step 3 of the docstring.
    pointer = 1
    queue = []
    for v in range(k):
        if ring.ear[v]:
            queue.append(pointer + (v - 1) % k)
    heapq.heapify(queue)
    t = 0
    remaining = k
    while remaining > 3:
        while queue and (queue[0] < pointer or not ring.ear[queue[0] % k]):
            heapq.heappop(queue)
        if queue:
            position = heapq.heappop(queue)
            i = position % k
        else:
            work[FALLBACKS] += 1
            start = pointer % k
            i = most_convex(ring.turn, best, start)
            position = pointer + (i - start) % k
        a, b = ring.prev[i], ring.next[i]
        out[t, 0], out[t, 1], out[t, 2] = a, i, b
        t += 1
        ring.next[a] = b
        ring.prev[b] = a
        remaining -= 1
        ring.ear[i] = False
        tournament_set(ring.turn, best, i, False)
        if ring.candidate[i]:
            set_candidate(tree, ring, i, False)
        # Only a and b have new neighbours: their turns and candidacy first,
        # then their ear flags (each ear test sees the other's candidacy).
        for v in (a, b):
            ring.turn[v] = orient(xs, ys, ring.prev[v], v, ring.next[v])
            tournament_set(ring.turn, best, v, True)
            candidate = is_candidate(xs, ys, marked, ring, v)
            if candidate != ring.candidate[v]:
                set_candidate(tree, ring, v, candidate)
        ring.ear[a] = is_ear(xs, ys, tree, ring, stack, work, a)
        ring.ear[b] = is_ear(xs, ys, tree, ring, stack, work, b)
        pointer = position + (b - i) % k
        if ring.ear[a]:
            heapq.heappush(queue, pointer + (a - b) % k)
        if ring.ear[b]:
            heapq.heappush(queue, pointer)
    i = pointer % k
    out[t, 0], out[t, 1], out[t, 2] = ring.prev[i], i, ring.next[i]


# -- running it -------------------------------------------------------------------------


def shared_points(xs, ys) -> np.ndarray:
    """(k,) bool: whether each corner's point ``(xs, ys)`` occurs more than once
    (exact equality, as in the specification's coincidence rule; -0.0 == 0.0)."""
    k = len(xs)
    pts = np.c_[np.asarray(xs, np.float64), np.asarray(ys, np.float64)] + 0.0  # -0.0 -> 0.0
    order = np.lexsort((pts[:, 1], pts[:, 0]))
    same = np.all(pts[order[1:]] == pts[order[:-1]], axis=1)
    shared = np.zeros(k, dtype=bool)
    shared[order[1:][same]] = True
    shared[order[:-1][same]] = True
    return shared


def clip_indexed(xs, ys, *, kernel: str | None = None, work=None) -> np.ndarray:
    """Ear-clip projected corners ``xs, ys`` (k,), ``k >= 4``, CCW, |coordinates|
    < 1: the (k - 2, 3) int64 triangles of the specification.

    ``kernel`` (:mod:`refsim.kernels`): "compiled" runs the numba build of
    this module's source, "readable" the source as Python. ``work``, if
    given, is an int64 array (4,) that receives the counters of
    :func:`clip_ears`.
    """
    xs = np.ascontiguousarray(xs, dtype=np.float64)
    ys = np.ascontiguousarray(ys, dtype=np.float64)
    k = len(xs)
    kernel = choose_kernel(kernel)
    build, clip = CORNER_TREE.pick(kernel), EAR_CLIPPING.pick(kernel)
    room = 2 * k
    perm = np.arange(k, dtype=np.int64)
    leaf = np.empty(k, np.int64)
    first, end, child, parent = (np.empty(room, np.int64) for _ in range(4))
    xmin, xmax, ymin, ymax = (np.empty(room, np.float64) for _ in range(4))
    m = build(xs, ys, perm, leaf, first, end, child, parent, xmin, xmax, ymin, ymax, LEAF_SIZE)
    tree = CornerTree(perm, leaf, first[:m], end[:m], child[:m], parent[:m], xmin[:m],
                      xmax[:m], ymin[:m], ymax[:m], np.zeros(m, np.int64))
    ring = Ring(np.empty(k, np.int64), np.empty(k, np.int64), np.empty(k, np.float64),
                np.zeros(k, bool), np.zeros(k, bool))
    size = 1 << (k - 1).bit_length()  # the smallest power of two >= k
    best = np.empty(2 * size, np.int64)
    out = np.empty((k - 2, 3), np.int64)
    counters = np.zeros(4, np.int64) if work is None else work
    clip(xs, ys, shared_points(xs, ys), tree, ring, best, out, counters)
    return out
