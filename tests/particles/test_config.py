"""ParticleConfig validation: every bad value names its key."""

from __future__ import annotations

import numpy as np
import pytest

from refsim.errors import SceneError
from refsim.particles.config import ParticleConfig

BAD = [
    ("count", 0), ("count", 2.5), ("count", True), ("seed", -1),
    ("box_lo", (0.0, 0.0)), ("box_lo", (0.0, np.nan, 0.0)), ("box_hi", (9.0, 0.0, 0.0)),
    ("speed_min", -1.0), ("speed_max", np.inf), ("gravity", -9.81), ("drag", -0.1),
    ("drag", "0.1"), ("drag_model", "cubic"), ("mass", 0.0), ("restitution", 1.5),
    ("friction", -0.1), ("half_size", 0.0), ("walls", "yes"), ("solver", "rk5"),
    ("step", 0.0), ("step", np.nan),
]


@pytest.mark.parametrize(("field", "value"), BAD)
def test_bad_value_names_the_key(field, value):
    with pytest.raises(SceneError) as info:
        ParticleConfig(**{field: value})
    assert info.value.key.startswith("particles.")
    print(info.value)


def test_box_hi_below_box_lo():
    with pytest.raises(SceneError) as info:
        ParticleConfig(box_lo=(0.0, 0.0, 0.0), box_hi=(1.0, -1.0, 1.0))
    assert info.value.key == "particles.box_hi"


def test_speed_max_below_speed_min():
    with pytest.raises(SceneError) as info:
        ParticleConfig(speed_min=3.0, speed_max=2.0)
    assert info.value.key == "particles.speed_max"


def test_defaults_are_valid_and_frozen():
    config = ParticleConfig()
    with pytest.raises(AttributeError):
        config.count = 5                                  # type: ignore[misc]
    assert config.field_names()[0] == "count"


def test_initial_state_is_reproducible_and_inside_the_box():
    config = ParticleConfig(count=500, seed=7, box_lo=(-1, 0, 2), box_hi=(1, 0.5, 3),
                            speed_min=2.0, speed_max=3.0)
    x1, v1 = config.initial_state()
    x2, v2 = config.initial_state()
    assert x1.tobytes() == x2.tobytes() and v1.tobytes() == v2.tobytes()
    assert x1.shape == (500, 3) and x1.dtype == np.float64
    assert (x1 >= [-1, 0, 2]).all() and (x1 <= [1, 0.5, 3]).all()
    speed = np.linalg.norm(v1, axis=1)
    assert (speed >= 2.0 - 1e-12).all() and (speed <= 3.0 + 1e-12).all()
