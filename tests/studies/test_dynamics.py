"""The C11 and C12 measurements gate on what the report states."""

from __future__ import annotations

import pytest

from refsim.dynamics.choices import choices
from refsim.studies.dynamics import (
    REST_SPEED,
    measure_energy,
    measure_interpenetration,
    measure_spin,
)


def test_c12_seed_spin_survives_and_corrected_comes_to_rest():
    seed, corrected = measure_spin(duration=5.0)
    print(f"final |w|: seed {seed.final_spin:.3g}, corrected {corrected.final_spin:.3g} rad/s")
    assert seed.model == "seed" and corrected.model == "impulse"
    assert not seed.at_rest and seed.final_spin == pytest.approx(5.0, rel=1e-3)
    assert seed.spin_normal[-1] == pytest.approx(5.0, rel=1e-12)   # w . N never changes
    assert corrected.at_rest
    assert corrected.rotational_energy[-1] < 1e-6 * corrected.rotational_energy[0]


def test_c11_seed_interpenetrates_when_stacked_corrected_never():
    rows = measure_interpenetration(cases=("stack",), duration=1.5)
    by = {r.response: r for r in rows}
    print({k: (r.interpenetrating, r.longest_run) for k, r in by.items()})
    assert by["seed"].interpenetrating > 100 and by["seed"].longest_run > 100
    assert by["impulse"].interpenetrating == 0
    assert by["impulse"].contacts >= 1                  # the bodies did meet


def test_energy_of_the_corrected_model_does_not_rise_at_bounces():
    seed, corrected = measure_energy(duration=3.0)
    print(f"max rise: seed {seed.max_rise:.3g} J, corrected {corrected.max_rise:.3g} J")
    assert corrected.energy[-1] < corrected.energy[0]
    assert corrected.max_rise < 2e-3 * corrected.energy[0]
    assert REST_SPEED > 0


def test_choices_are_listed_for_the_report():
    tags = [tag for tag, _ in choices()]
    assert tags[:3] == ["A1", "A2", "A3"] and "D1" in tags and "D8" in tags
