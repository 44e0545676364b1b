"""A sweep's tasks: a call of a module-level function, a key, a seed.

A :class:`Task` is ``function(seed=seed, **kwargs)`` with a ``key`` unique in
its sweep. The function is pickled by reference (its module and name), so a
worker process or a Dask worker imports it; a lambda or a nested function
would work in-process and nowhere else, so it is refused on every backend.
The arguments are plain data (:mod:`refsim.sweep.records`), so that a result
store can tell whether a stored result belongs to the same call: pass a
scene by its file name, not as a loaded :class:`refsim.Scene`.

Seeds
-----
A task's seed depends on the sweep's seed and the task's key only:

    seed = SeedSequence(sweep_seed, spawn_key=words(SHA-256(key))).generate_state(1, uint64)

``SeedSequence.spawn(n)`` gives child ``i`` the spawn key ``(i,)``; here the
key's hash takes the index's place. Index-based seeds would change when a
task is inserted, removed or moved, so an extended sweep would silently
redraw every later task, and its stored results would no longer match; with
key-based seeds, adding tasks to a sweep (or running a subset) leaves every
other task's seed, and so its result, as it was. SeedSequence mixes the
sweep seed and the key's 256 bits into well-spread state (O'Neill,
"Developing a seed_seq alternative", 2015; numpy's ``SeedSequence``), so
nearby sweep seeds or similar keys give unrelated streams. The seed is a
64-bit integer: ``numpy.random.default_rng(seed)`` takes it as it is; two
tasks of a sweep of a million share a seed with probability about 3e-8.

Fingerprints
------------
``fingerprint(task, seed)`` is the SHA-256 of the canonical JSON of the
function's import name, the arguments and the seed. A store keeps it beside
each result and refuses a task whose fingerprint differs (same key, another
call). Renaming or moving the function changes it; editing its body does not
(a store cannot see code: delete the store when the code changes results).

Cost: O(size of the arguments) per task.
"""

from __future__ import annotations

import hashlib
import importlib
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any

import numpy as np

from refsim.errors import ArgumentTypeError
from refsim.sweep.records import canonical, digest


@dataclass(frozen=True)
class Task:
    """One run of a sweep: ``function(seed=seed, **kwargs)``.

    Parameters
    ----------
    key : str
        Unique in the sweep; names the task's result file and its seed.
    function : callable
        A function defined at the top level of an importable module, taking
        ``seed`` (an int) as a keyword argument and returning a plain record.
    kwargs : mapping of str to plain data
        Its other keyword arguments (no ``seed``); kept as a read-only copy,
        so that the call cannot change after its fingerprint is taken.

    Raises
    ------
    ArgumentTypeError
        For a key that is not a non-empty string, a function that workers
        cannot import by name, or arguments that are not plain data.
    """

    key: str
    function: Callable
    kwargs: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self):
        if not isinstance(self.key, str) or not self.key:
            raise ArgumentTypeError(f"a task's key must be a non-empty str, got {self.key!r}")
        function_name(self.function, self.key)           # raises for a lambda or a closure
        if not isinstance(self.kwargs, Mapping):
            raise ArgumentTypeError(f"task {self.key!r}: kwargs must be a mapping, "
                                    f"got {type(self.kwargs).__name__}")
        kwargs = dict(self.kwargs)
        if "seed" in kwargs:
            raise ArgumentTypeError(f"task {self.key!r}: 'seed' is given by the sweep, "
                                    "not in kwargs")
        try:
            canonical(kwargs)
        except (TypeError, ValueError) as error:
            raise ArgumentTypeError(f"task {self.key!r}: kwargs must be plain data: "
                                    f"{error}") from None
        object.__setattr__(self, "kwargs", MappingProxyType(kwargs))   # read-only

    def __reduce__(self):
        # pickled as the call that makes it (a read-only mapping does not pickle)
        return Task, (self.key, self.function, dict(self.kwargs))


def function_name(function, key: str = "?") -> str:
    """``"module:qualname"`` of a function that can be imported by that name.

    Pickle sends a function as this name; a worker imports it. A lambda, a
    function defined inside another, or one rebound under another name
    cannot be found that way, so :class:`ArgumentTypeError` names the task.
    """
    module = getattr(function, "__module__", None)
    qualname = getattr(function, "__qualname__", None)
    if not callable(function) or module is None or qualname is None:
        raise ArgumentTypeError(f"task {key!r}: function must be a module-level function, "
                                f"got {function!r}")
    try:
        found = importlib.import_module(module)
        for part in qualname.split("."):
            found = getattr(found, part)
    except (ImportError, AttributeError):
        found = None
    if found is not function:
        raise ArgumentTypeError(
            f"task {key!r}: function {module}.{qualname} cannot be imported by name "
            "(a lambda or a nested function runs in-process only); define it at the "
            "top level of a module")
    return f"{module}:{qualname}"


def task_seed(sweep_seed: int, key: str) -> int:
    """The seed of the task ``key`` in a sweep seeded ``sweep_seed`` (see the
    module docstring): a 64-bit non-negative int, the same on every machine."""
    hashed = hashlib.sha256(key.encode("utf-8")).digest()
    words = tuple(int.from_bytes(hashed[i:i + 4], "little") for i in range(0, 32, 4))
    sequence = np.random.SeedSequence(sweep_seed, spawn_key=words)
    return int(sequence.generate_state(1, dtype=np.uint64)[0])


def fingerprint(task: Task, seed: int) -> str:
    """SHA-256 (hex) of the call ``task`` makes with ``seed``."""
    return digest(canonical({"function": function_name(task.function, task.key),
                             "kwargs": dict(task.kwargs), "seed": seed}))
