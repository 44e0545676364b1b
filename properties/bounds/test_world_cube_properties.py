"""Laws of the world cube test (seed S3), on dyadic boxes (exact arithmetic).

- A wall is crossed exactly when the box is not inside the cube on that side.
- Pushing by the correction puts a box that fits back inside (touching the
  wall it crossed); a box too wide to fit touches the wall it crossed, or
  ends centred when it crossed both.
- Translating box and cube together changes nothing (the test is per axis
  and relative).
"""

from __future__ import annotations

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from refsim.bounds.world_cube import world_cube_test

DYADIC = st.integers(min_value=-64, max_value=64).map(lambda k: k / 8.0)
VECTOR = st.lists(DYADIC, min_size=3, max_size=3).map(np.array)
HALF_SIZE = st.integers(min_value=1, max_value=48).map(lambda k: k / 8.0)


@st.composite
def boxes(draw):
    a, b = draw(VECTOR), draw(VECTOR)
    return np.minimum(a, b), np.maximum(a, b)


@given(box=boxes(), half_size=HALF_SIZE)
def test_crossed_exactly_when_outside(box, half_size):
    lo, hi = box
    result = world_cube_test(lo, hi, half_size=half_size)
    assert result.crossed[:, 0].tolist() == (lo < -half_size).tolist()
    assert result.crossed[:, 1].tolist() == (hi > half_size).tolist()
    assert result.any == bool(((lo < -half_size) | (hi > half_size)).any())


@given(box=boxes(), half_size=HALF_SIZE)
def test_correction_brings_the_box_back(box, half_size):
    lo, hi = box
    before = world_cube_test(lo, hi, half_size=half_size)
    new_lo, new_hi = lo + before.correction, hi + before.correction
    fits = (hi - lo) <= 2.0 * half_size
    assert ((new_lo >= -half_size) & (new_hi <= half_size))[fits].all()
    after = world_cube_test(new_lo, new_hi, half_size=half_size)
    assert not after.crossed[fits].any()
    # Too wide to fit: crossing one wall, the box is pushed to touch it;
    # crossing both, it is centred.
    low, high = before.crossed[:, 0], before.crossed[:, 1]
    assert (new_lo == -half_size)[~fits & low & ~high].all()
    assert (new_hi == half_size)[~fits & high & ~low].all()
    assert (new_lo + new_hi == 0.0)[low & high].all()


@given(box=boxes(), half_size=HALF_SIZE, offset=VECTOR)
def test_translating_box_and_cube_together_changes_nothing(box, half_size, offset):
    lo, hi = box
    centred = world_cube_test(lo, hi, half_size=half_size)
    moved = world_cube_test(lo + offset, hi + offset, cube_lo=offset - half_size,
                            cube_hi=offset + half_size)
    assert np.array_equal(centred.below, moved.below)
    assert np.array_equal(centred.above, moved.above)
