"""The C11 and C12 measurements gate on what the report states."""

from __future__ import annotations

import numpy as np
import pytest

from refsim.dynamics.choices import choices
from refsim.dynamics.simulate import simulate
from refsim.engines.refsim_engines import as_posed, as_posed_seed_wall_speed
from refsim.engines.refsim_engines import seed as seed_engine
from refsim.errors import StateError
from refsim.studies.dynamics import (
    REST_SPEED,
    measure_energy,
    measure_interpenetration,
    measure_spin,
)


class OwnModel:
    """An engine with a model of its own: it runs every scene with the seed's
    rotation, whatever the scene names, and records what it was given."""

    name = "own-model"

    def __init__(self):
        self.given = []

    def simulate(self, scene, *, every: int = 1):
        from dataclasses import replace

        self.given.append((scene, every))
        return simulate(replace(scene, dynamics=replace(scene.dynamics, rotation="seed")),
                        every=every)


def test_c12_seed_spin_survives_and_corrected_comes_to_rest():
    seed, corrected = measure_spin(duration=5.0)
    print(f"final |w|: seed {seed.final_spin:.3g}, corrected {corrected.final_spin:.3g} rad/s")
    assert seed.model == "seed" and corrected.model == "impulse"
    assert seed.engine == corrected.engine == "refsim"          # refsim as posed, by default
    assert not seed.at_rest and seed.final_spin == pytest.approx(5.0, rel=1e-3)
    assert seed.spin_normal[-1] == pytest.approx(5.0, rel=1e-12)   # w . N never changes
    assert corrected.at_rest
    assert corrected.rotational_energy[-1] < 1e-6 * corrected.rotational_energy[0]


def test_c11_seed_interpenetrates_when_stacked_corrected_never():
    rows = measure_interpenetration(cases=("stack",), duration=1.5)
    by = {r.response: r for r in rows}
    print({k: (r.interpenetrating, r.longest_run) for k, r in by.items()})
    assert {r.engine for r in rows} == {"refsim"}
    assert by["seed"].interpenetrating > 100 and by["seed"].longest_run > 100
    assert by["impulse"].interpenetrating == 0
    assert by["impulse"].contacts >= 1                  # the bodies did meet


def test_energy_of_the_corrected_model_does_not_rise_at_bounces():
    seed, corrected = measure_energy(duration=3.0)
    print(f"max rise: seed {seed.max_rise:.3g} J, corrected {corrected.max_rise:.3g} J")
    assert corrected.energy[-1] < corrected.energy[0]
    assert corrected.max_rise < 2e-3 * corrected.energy[0]
    assert seed.engine == corrected.engine == "refsim"
    assert REST_SPEED > 0


def test_an_engine_with_its_own_model_runs_the_scene_once_under_its_name():
    # refsim poses each rotation; the other engine gets the same scene (the
    # duration applied, the same frame stride) once, and its series is its
    # own: here it runs the seed's rotation, so it matches refsim's "seed"
    own = OwnModel()
    rows = measure_spin(engines=[as_posed(), own], duration=1.0)
    assert [(r.engine, r.model) for r in rows] == [
        ("refsim", "seed"), ("refsim", "impulse"), ("own-model", "own-model")]
    (scene, every), = own.given
    assert scene.integration.duration == 1.0 and scene.dynamics.rotation == "seed"  # the file's
    assert every == 1 and len(rows[2].t) == scene.integration.n_steps + 1
    assert np.array_equal(rows[2].spin, rows[0].spin)
    assert not np.array_equal(rows[1].spin, rows[0].spin)


def test_two_series_of_one_name_are_refused_before_any_run():
    # refsim as posed and with the seed's wall speed both pose the scene's
    # rotation models: their "seed" series would share a name in the chart
    own = OwnModel()
    with pytest.raises(StateError, match="engines 'refsim' and 'refsim-seed-wall-speed' both "
                                         "give a spin series named 'seed'"):
        measure_spin(engines=[own, as_posed(), as_posed_seed_wall_speed()], duration=0.1)
    assert own.given == []                              # nothing ran


@pytest.mark.parametrize("study", [measure_interpenetration, measure_energy])
def test_a_study_of_the_scenes_model_refuses_an_engine_with_its_own(study):
    # the seed engine overrides the scene's rotation and body response: it
    # cannot run a study that varies them
    with pytest.raises(StateError, match="'refsim-seed' runs a model of its own"):
        study(engine=seed_engine())


def test_choices_are_listed_for_the_report():
    tags = [tag for tag, _ in choices()]
    assert tags[:3] == ["A1", "A2", "A3"] and "D1" in tags and "D8" in tags
