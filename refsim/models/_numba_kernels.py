"""The indexed ear clipping of :mod:`refsim.models.ear_index`, compiled by numba.

Not a second copy: numba compiles the readable functions themselves. The
helpers are registered with ``register_jitable`` (they stay plain Python
functions when called from Python) and the two entry points are wrapped here,
at module level, so that numba's on-disk cache (``cache=True``, keyed by the
source file and the function) is found by every later process: the compile
is paid once per machine.

Arithmetic: numba compiles without fast-math, so each operation is rounded
once, as in Python; the pruning argument of ear_index (step 2) and the
comparison with the specification hold for both. tests/models/test_ear_index.py
checks compiled against uncompiled, bit for bit.

This module imports numba at import time; import it only when the compiled
kernel is chosen (:data:`refsim.kernels.CORNER_TREE`, :data:`refsim.kernels.EAR_CLIPPING`).
"""

from __future__ import annotations

import numba
from numba.extending import register_jitable

from refsim.models import ear_index

#: :func:`refsim.kernels.sources_digest` of the refsim modules this one imports:
#: an edit there must change this line, so that numba renews its cache of
#: this module (tests/test_kernels.py checks it).
SOURCES_DIGEST = "8e4159f4b5ec5dca"

for _helper in (ear_index.orient, ear_index.orient_error, ear_index.blocks,
                ear_index.is_candidate, ear_index.mark_contacts,
                ear_index.set_candidate, ear_index.box_outside_edge, ear_index.is_ear,
                ear_index.better, ear_index.tournament_set,
                ear_index.tournament_first_best, ear_index.most_convex):
    register_jitable(_helper)

build_tree = numba.njit(cache=True)(ear_index.build_tree)
clip_ears = numba.njit(cache=True)(ear_index.clip_ears)
