"""Names of a package imported on first use (PEP 562's module ``__getattr__``).

A package that re-exports names from its modules, but should not import
them all when it is imported (a pytest plugin loaded on every test run, a
view that must load without the simulation), lists them as
``{name: module}`` and takes its ``__getattr__`` and ``__dir__`` from
:func:`exports`. ``refsim/__init__.py`` keeps its own copy, which also
finds subpackages: the package root imports nothing of refsim.
"""

from __future__ import annotations

import importlib
import sys
from collections.abc import Callable


def exports(package: str, names: dict[str, str]
            ) -> tuple[Callable[[str], object], Callable[[], list[str]]]:
    """``(__getattr__, __dir__)`` for ``package`` (its dotted name): an
    attribute in ``names`` is imported from its module on first use and
    kept in the package; any other raises AttributeError."""
    def __getattr__(name: str):
        module = names.get(name)
        if module is None:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        value = getattr(importlib.import_module(module), name)
        setattr(sys.modules[package], name, value)
        return value

    def __dir__() -> list[str]:
        return sorted(set(vars(sys.modules[package])) | set(names))

    return __getattr__, __dir__
