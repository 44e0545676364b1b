"""Laws of the AC3D reader and writer (refsim.models.ac3d, seed S1).

1. Round trip: any mesh written and read back is identical, bit for bit.
2. Fixed point: writing what was read gives the same text.
3. Robustness: a damaged file (cut short, a byte or token replaced, a line
   deleted or duplicated) either parses or raises ModelError; nothing else
   escapes (no IndexError, ValueError, UnicodeDecodeError, RecursionError...).
"""

from __future__ import annotations

import tempfile
import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from properties.models.strategies import meshes
from refsim.errors import ModelError, ModelWarning
from refsim.models.ac3d import format_ac3d, parse_ac3d, read_ac3d
from refsim.models.mesh import Mesh
from tests.helpers import assert_meshes_identical

#: Tokens a mutation may put in place of another: keywords in the wrong place,
#: bad numbers, stray quotes, huge counts.
TOKENS = ["OBJECT", "poly", "world", "kids", "numvert", "numsurf", "SURF", "mat", "refs",
          "data", "rot", "loc", "name", "MATERIAL", "rgb", "-1", "0", "1", "3", "7",
          "99999999999", "1" * 40, "0x1", "0x2", "0xFFFFFFFFFFFFFFFFF", "1e999", "nan", "inf",
          "-0.0", "1e-320", '"', '"a b"', '""', "\t", "x", "\u00e9", "\ufeff"]


@pytest.fixture(scope="module")
def folder():
    with tempfile.TemporaryDirectory() as name:
        yield Path(name)


def _parses_or_model_error(read):
    """Run ``read``; return the mesh, or None when it raised ModelError."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ModelWarning)
        try:
            mesh = read()
        except ModelError as err:
            assert "\n" not in str(err)
            return None
    # whatever parsed is a valid mesh
    assert isinstance(mesh, Mesh)
    assert mesh.n_faces >= 1
    assert 0 <= mesh.faces.min() and mesh.faces.max() < mesh.n_vertices
    assert np.isfinite(mesh.vertices).all()
    return mesh


@given(meshes())
def test_write_then_read_is_identity(mesh):
    assert_meshes_identical(mesh, parse_ac3d(format_ac3d(mesh)))


@given(meshes())
def test_writing_what_was_read_is_a_fixed_point(mesh):
    text = format_ac3d(mesh)
    assert format_ac3d(parse_ac3d(text)) == text


@given(meshes(), st.data())
def test_truncated_files_parse_or_raise_model_error(folder, mesh, data):
    raw = format_ac3d(mesh).encode("utf-8")
    cut = data.draw(st.integers(min_value=0, max_value=len(raw) - 1))
    path = folder / "cut.ac"
    path.write_bytes(raw[:cut])  # may split a UTF-8 character: read as Latin-1
    _parses_or_model_error(lambda: read_ac3d(path))


@given(meshes(), st.data())
def test_mutated_bytes_parse_or_raise_model_error(folder, mesh, data):
    raw = bytearray(format_ac3d(mesh).encode("utf-8"))
    for _ in range(data.draw(st.integers(min_value=1, max_value=3))):
        at = data.draw(st.integers(min_value=0, max_value=len(raw) - 1))
        raw[at] = data.draw(st.integers(min_value=0, max_value=255))
    path = folder / "mutated.ac"
    path.write_bytes(bytes(raw))
    _parses_or_model_error(lambda: read_ac3d(path))


@given(meshes(max_vertices=6, max_faces=4), st.data())
def test_mutated_tokens_and_lines_parse_or_raise_model_error(mesh, data):
    lines = format_ac3d(mesh).split("\n")
    for _ in range(data.draw(st.integers(min_value=1, max_value=3))):
        k = data.draw(st.integers(min_value=0, max_value=len(lines) - 1))
        action = data.draw(st.sampled_from(["token", "delete", "duplicate", "insert"]))
        if action == "token":
            words = lines[k].split(" ")
            j = data.draw(st.integers(min_value=0, max_value=len(words) - 1))
            words[j] = data.draw(st.sampled_from(TOKENS))
            lines[k] = " ".join(words)
        elif action == "delete":
            del lines[k]
            if not lines:
                lines = [""]
        elif action == "duplicate":
            lines.insert(k, lines[k])
        else:
            lines.insert(k, " ".join(data.draw(st.lists(st.sampled_from(TOKENS), max_size=4))))
    text = "\n".join(lines)
    _parses_or_model_error(lambda: parse_ac3d(text))


@given(meshes(max_vertices=6, max_faces=4), st.data())
def test_a_valid_data_block_anywhere_in_an_object_changes_nothing(mesh, data):
    # Insert "data n" plus n arbitrary characters after an object's name line:
    # the blob is skipped by count, whatever it holds.
    text = format_ac3d(mesh)
    blob = data.draw(st.text(st.characters(blacklist_categories=("Cs",)), max_size=30))
    lines = text.split("\n")
    k = lines.index("OBJECT poly") + 2  # after 'name'
    n = len(blob.replace("\r\n", "\n").encode("utf-8"))
    if blob.endswith("\r") or not blob.endswith("\n"):
        blob += "\n"
    patched = "\n".join(lines[:k]) + f"\ndata {n}\n{blob}" + "\n".join(lines[k:])
    assert_meshes_identical(mesh, parse_ac3d(patched))
