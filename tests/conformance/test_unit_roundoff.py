"""An engine that computes in float32 declares unit_roundoff = 2**-24: its
misses within float32 rounding are "tolerance", not "bug"."""

from __future__ import annotations

import numpy as np
import pytest

from refsim.conformance.cases_boxes import box_cases
from refsim.conformance.checks_geometry import check_aabb_encloses
from refsim.engines import declarations
from refsim.errors import OptionError


class Float32Boxes:
    """The box of the vertices transformed in float32, as a float32
    geometry library computes it."""

    name = "float32-boxes"

    def __init__(self, unit_roundoff=None):
        if unit_roundoff is not None:
            self.unit_roundoff = unit_roundoff

    def aabb(self, vertices, pose):
        R, t = (np.asarray(p, dtype=np.float32) for p in pose)
        world = np.asarray(vertices, dtype=np.float32) @ R.T + t
        return world.min(axis=0).astype(np.float64), world.max(axis=0).astype(np.float64)


@pytest.fixture(scope="module")
def boxes():
    return box_cases(120, 0)


def test_float32_boxes_are_bugs_undeclared_and_tolerance_declared(boxes):
    undeclared = check_aabb_encloses(Float32Boxes(), boxes)
    assert undeclared.classes.get("bug", 0) > 10
    declared = check_aabb_encloses(Float32Boxes(2.0 ** -24), boxes)
    assert declared.failed == undeclared.failed            # the same cases miss ...
    assert set(declared.classes) == {"tolerance"}          # ... all within float32's rounding
    example = next(e for e in declared.examples if not e.get("shrunk"))
    assert example["engine_rounding_bound_metres"] >= example["excess_metres"]


def test_a_box_short_by_more_than_float32_rounding_is_still_a_bug(boxes):
    class ShortBoxes(Float32Boxes):
        """1e-4 of each side's magnitude (plus 1e-4 m) inside: far beyond 2**-24."""

        def aabb(self, vertices, pose):
            lo, hi = super().aabb(vertices, pose)
            return lo + 1e-4 * (np.abs(lo) + 1.0), hi - 1e-4 * (np.abs(hi) + 1.0)

    result = check_aabb_encloses(ShortBoxes(2.0 ** -24), boxes)
    assert result.failed == len(boxes) and result.classes == {"bug": len(boxes)}


@pytest.mark.parametrize("value", [0.0, 1.0, 2.0 ** -60, True, "float32"])
def test_unit_roundoff_is_checked(value):
    class Engine:
        name = "e"
        unit_roundoff = value

    with pytest.raises(OptionError, match="unit_roundoff must be a number"):
        declarations(Engine())
