"""Expected-failures files: the format, its errors (naming the line), and
what a declaration does to a check's status."""

from __future__ import annotations

from dataclasses import replace

import pytest

from refsim.conformance.expected import (
    apply_expected,
    parse_expected,
    read_expected,
    shipped_expected_failures,
)
from refsim.conformance.results import tally
from refsim.conformance.shipped import SHIPPED_ENGINES
from refsim.errors import OptionError


def test_lines_comments_and_classes():
    found = parse_expected("# why\n\ntriangles.agreement[touching,tolerance]  float test\n"
                           "rigid.energy   pumps energy in\n")
    assert set(found) == {"triangles.agreement", "rigid.energy"}
    assert found["triangles.agreement"].classes == ("touching", "tolerance")
    assert found["triangles.agreement"].reason == "float test"
    assert found["triangles.agreement"].line == 3
    assert found["rigid.energy"].classes is None
    assert found["rigid.energy"].reason == "pumps energy in"


@pytest.mark.parametrize("text, line, phrase", [
    ("triangles.agreement\n", 1, "a reason is required"),
    ("# ok\ntriangles.nope  x\n", 2, "unknown check 'triangles.nope'"),
    ("\n\naabb.tight[fuzzy]  x\n", 3, "unknown class fuzzy"),
    ("aabb.tight[]  x\n", 1, "unknown class (none given)"),
    ("aabb.tight  a\naabb.tight  b\n", 2, "already declared on line 1"),
    ("not a declaration at all\n", 1, "expected 'capability.check[classes]  reason'"),
    ("aabb.tight[tolerance <= wide]  x\n", 1,
     "the bound of tolerance must be a finite number of metres >= 0, got 'wide'"),
    ("aabb.tight[tolerance <= -1e-6]  x\n", 1, "got '-1e-6'"),
    ("aabb.tight[tolerance <= nan]  x\n", 1, "got 'nan'"),
    ("rigid.energy[bug <= 0.1]  x\n", 1, "rigid.energy: takes no bound (it measures no length"),
    ("aabb.tight[bug, bug]  x\n", 1, "class bug is named twice"),
    ("aabb.tight[tolerance < 1e-6]  x\n", 1, "unknown class tolerance < 1e-6"),
])
def test_malformed_lines_name_the_file_and_line(text, line, phrase):
    with pytest.raises(OptionError) as info:
        parse_expected(text, "x.txt")
    assert str(info.value).startswith(f"x.txt:{line}: ")
    assert phrase in str(info.value)


def test_bounds_and_spaces_in_the_class_list():
    found = parse_expected("triangles.agreement [touching, tolerance <= 1e-6, bug<=2.5e-11]  gjk\n")
    declared = found["triangles.agreement"]
    assert declared.classes == ("touching", "tolerance", "bug")
    assert declared.bounds == {"tolerance": 1e-6, "bug": 2.5e-11}
    assert declared.reason == "gjk"


def _measured(classes, largest):
    return replace(_result(classes), largest_miss_metres=largest)


def test_a_bound_accepts_a_class_only_within_it():
    declared = parse_expected("triangles.agreement[touching, bug <= 1e-10]  float test\n")
    within = apply_expected(_measured({"touching": 1, "bug": 2}, {"touching": 0.0, "bug": 8e-11}),
                            declared)
    assert within.status == "xfailed"
    beyond = apply_expected(_measured({"bug": 2}, {"bug": 3e-9}), declared)
    assert beyond.status == "failed"
    assert beyond.reason == ("declared bug <= 1e-10 m (measured up to 3e-09 m): float test")


def test_crash_is_accepted_only_when_named():
    crashed = _result({"crash": 1, "bug": 1})
    anything = apply_expected(crashed, parse_expected("triangles.agreement  float test\n"))
    assert anything.status == "failed"
    assert anything.reason == "a crash is accepted only when named; also crash: float test"
    bug = apply_expected(crashed, parse_expected("triangles.agreement[bug]  float test\n"))
    assert bug.status == "failed" and "also crash" in bug.reason
    named = apply_expected(crashed, parse_expected("triangles.agreement[crash,bug]  raises\n"))
    assert named.status == "xfailed"


def test_unreadable_file_is_named(tmp_path):
    with pytest.raises(OptionError, match="cannot read the expected-failures file"):
        read_expected(tmp_path / "absent.txt")


def _result(classes):
    outcomes = [None] * 3 + [c for c, n in classes.items() for _ in range(n)]
    return tally("triangles", "agreement", outcomes)


def test_declarations_set_the_status():
    limited = parse_expected("triangles.agreement[touching]  float test\n")
    anything = parse_expected("triangles.agreement  float test\n")
    assert apply_expected(_result({"touching": 2}), limited).status == "xfailed"
    assert apply_expected(_result({"touching": 2}), limited).reason == "float test"
    outside = apply_expected(_result({"touching": 2, "bug": 1}), limited)
    assert outside.status == "failed" and "also bug" in outside.reason
    assert apply_expected(_result({"bug": 1}), anything).status == "xfailed"
    assert apply_expected(_result({}), anything).status == "xpassed"
    assert apply_expected(_result({"bug": 1}), {}).status == "failed"
    assert apply_expected(_result({}), {}).status == "passed"


def test_every_shipped_engine_has_a_valid_file():
    for name in SHIPPED_ENGINES:
        path = shipped_expected_failures(name)
        assert path is not None and path.name == f"{name}.txt"
        declared = read_expected(path)
        assert all(d.reason for d in declared.values()), name
        # every engine but refsim's corrected model declares a divergence;
        # the corrected model meets every check
        assert bool(declared) == (name != "refsim-corrected"), name
