"""Shared fixtures for the example-based tests."""

from __future__ import annotations

import pytest
from refsim.oracles import OracleUnavailable


@pytest.fixture
def oracle():
    """Call ``oracle(factory)`` to build an adapter, skipping with the reason
    when its engine is missing."""

    def build(factory, *args, **kwargs):
        try:
            return factory(*args, **kwargs)
        except OracleUnavailable as exc:
            pytest.skip(str(exc))

    return build
