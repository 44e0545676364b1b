"""Adapters to the independent engines refsim is checked against.

One module per engine; each converts conventions (units, frames, float32,
semantics) inside itself and nowhere else. The engines are optional
dependencies (``pip install -e '.[oracles]'``): an adapter imports its engine
only when used and raises :class:`OracleUnavailable` if it is missing. Tests
turn that into a skip that names the reason (``require`` in tests/conftest.py).
"""

from __future__ import annotations

import importlib


class OracleUnavailable(RuntimeError):
    """The engine behind an oracle is not installed or cannot run here."""


def import_engine(module: str, package: str):
    """Import an engine's module or raise :class:`OracleUnavailable`.

    ``package`` is the PyPI name to tell the user (e.g. ``python-fcl`` for
    module ``fcl``).
    """
    try:
        return importlib.import_module(module)
    except ImportError as exc:
        raise OracleUnavailable(
            f"oracle engine {package!r} is not installed "
            f"(pip install -e '.[oracles]'): {exc}") from None
