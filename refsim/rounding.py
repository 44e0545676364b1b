"""How far float64 rounding can move an orientation determinant.

These are Shewchuk's error bounds for the first, non-adaptive stage of his
orientation predicates: when the determinant computed in floats exceeds the
bound times its permanent (the same expansion with every term made
non-negative), its sign is the exact sign. The exact predicates of
:mod:`refsim.collision.predicates` filter with them, and so does the ear
clipping of :mod:`refsim.models.ear_index`; they live here, below both.

Reference: J. R. Shewchuk, "Adaptive Precision Floating-Point Arithmetic and
Fast Robust Geometric Predicates", Discrete & Computational Geometry 18
(1997), section 4.
"""

from __future__ import annotations

#: Machine epsilon in Shewchuk's sense: half an ulp of 1, 2**-53 for float64.
EPSILON = 2.0 ** -53

#: Shewchuk (1997) ``ccwerrboundA``: relative error bound of the float orient2d.
O2D_ERRBOUND_A = (3.0 + 16.0 * EPSILON) * EPSILON

#: Shewchuk (1997) ``o3derrboundA``: relative error bound of the float orient3d.
O3D_ERRBOUND_A = (7.0 + 56.0 * EPSILON) * EPSILON
