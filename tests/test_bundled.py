"""refsim.bundled: where the bundled data is found."""

from __future__ import annotations

import pytest

from refsim.bundled import model_path, models_dir
from refsim.errors import ModelError


def test_a_bundled_model_is_found_by_its_name():
    path = model_path("tetrahedron.ac")
    assert path == models_dir() / "tetrahedron.ac" and path.is_file()
    assert path.read_text().startswith("AC3D")


@pytest.mark.parametrize("name", ["no-such.ac", "../pyproject.toml", "models/cube.ac"])
def test_anything_else_names_the_bundled_models(name):
    with pytest.raises(ModelError) as caught:
        model_path(name)
    message = str(caught.value)
    assert message.startswith(f"{name}: not a bundled model") and "cube.ac" in message
