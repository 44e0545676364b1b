"""Records: what a task returns comes back as its JSON form, exactly."""

from __future__ import annotations

import math

import numpy as np
import pytest

from refsim.sweep.records import canonical, decode, encode


def test_floats_come_back_bit_for_bit():
    values = [0.1, 1 / 3, -0.0, 5e-324, 1.7976931348623157e308, math.pi * 1e-300]
    back = decode(encode(values))
    assert [v.hex() for v in back] == [v.hex() for v in values]
    assert math.isnan(decode(encode(math.nan))) and decode(encode(-math.inf)) == -math.inf


def test_numpy_values_tuples_and_int_keys_become_their_json_form():
    record = {"a": np.arange(3.0), "b": np.float32(0.5), "c": np.int64(7), "d": (1, 2),
              "e": np.bool_(True), 3: "three"}
    assert decode(encode(record)) == {"a": [0.0, 1.0, 2.0], "b": 0.5, "c": 7, "d": [1, 2],
                                      "e": True, "3": "three"}
    assert type(decode(encode(record))["c"]) is int


@pytest.mark.parametrize("value", [{1, 2}, b"bytes", object(), {"x": [complex(1, 2)]}])
def test_what_is_not_plain_data_is_refused_by_type(value):
    with pytest.raises(TypeError, match="is not a plain record"):
        encode(value)


def test_canonical_text_does_not_depend_on_dict_order():
    assert canonical({"b": 1, "a": {"d": 2, "c": 3}}) == '{"a":{"c":3,"d":2},"b":1}'
