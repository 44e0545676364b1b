"""The classes are defined once (refsim.conformance.results.CLASS_DEFINITIONS)
and the README's table says the same, class for class."""

from __future__ import annotations

from pathlib import Path

from refsim.conformance.results import CLASS_DEFINITIONS, CLASSES

README = Path(__file__).resolve().parents[2] / "README.md"


def test_readme_defines_every_class_as_the_code_does():
    rows = {}
    for line in README.read_text(encoding="utf-8").splitlines():
        if line.startswith("| `") and line.endswith(" |"):
            name, meaning = line[3:-2].split("` | ", 1)
            rows[name] = meaning
    assert {k: rows.get(k) for k in CLASSES} == CLASS_DEFINITIONS


def test_the_classes_run_from_the_most_to_the_least_serious():
    assert CLASSES == ("crash", "bug", "unmeasurable", "law", "known-divergence", "loose",
                       "tolerance", "touching", "coplanar")
