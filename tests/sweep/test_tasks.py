"""Tasks: key-based seeds, import-by-name functions, plain arguments, fingerprints."""

from __future__ import annotations

import numpy as np
import pytest

from refsim.errors import ArgumentTypeError
from refsim.sweep import Task, task_seed
from refsim.sweep.tasks import fingerprint, function_name
from tests.sweep import tasks


def test_a_seed_depends_on_the_sweep_seed_and_the_key_only():
    keys = [f"t{i}" for i in range(5)]
    seeds = [task_seed(7, key) for key in keys]
    extended = [task_seed(7, key) for key in ["new", *keys, "other"]]
    assert extended[1:-1] == seeds                 # adding tasks keeps the others' seeds
    assert len(set(seeds)) == len(seeds)
    assert task_seed(8, "t0") != seeds[0]
    assert all(0 <= s < 2**64 for s in seeds)


def test_the_seed_is_numpys_seed_sequence_spawned_by_the_keys_hash():
    # the value itself is part of the contract: stored results depend on it
    import hashlib

    digest = hashlib.sha256(b"t0").digest()
    words = tuple(int.from_bytes(digest[i:i + 4], "little") for i in range(0, 32, 4))
    expected = np.random.SeedSequence(7, spawn_key=words).generate_state(1, np.uint64)[0]
    assert task_seed(7, "t0") == int(expected)


def test_only_importable_functions_make_tasks():
    assert function_name(tasks.draws) == "tests.sweep.tasks:draws"
    with pytest.raises(ArgumentTypeError, match="cannot be imported by name"):
        Task("a", lambda seed: seed)

    def nested(*, seed):
        return seed

    with pytest.raises(ArgumentTypeError, match="'b'.*nested"):
        Task("b", nested)


@pytest.mark.parametrize("kwargs, phrase", [
    ({"seed": 3}, "given by the sweep"),
    ({"scene": object()}, "plain data"),
    ({"s": {1, 2}}, "plain data"),
    ([("n", 1)], "must be a mapping"),
])
def test_arguments_are_plain_data_without_a_seed(kwargs, phrase):
    with pytest.raises(ArgumentTypeError, match=phrase):
        Task("k", tasks.draws, kwargs)


@pytest.mark.parametrize("key", ["", None, 3])
def test_a_key_is_a_non_empty_string(key):
    with pytest.raises(ArgumentTypeError, match="key"):
        Task(key, tasks.draws)


def test_the_fingerprint_tells_calls_apart_and_ignores_dict_order():
    a = Task("k", tasks.draws, {"n": 4, "m": [1.5, 2]})
    same = Task("k", tasks.draws, {"m": [1.5, 2], "n": 4})
    assert fingerprint(a, 1) == fingerprint(same, 1)
    assert fingerprint(a, 1) != fingerprint(a, 2)
    assert fingerprint(a, 1) != fingerprint(Task("k", tasks.draws, {"n": 5, "m": [1.5, 2]}), 1)
    assert fingerprint(a, 1) != fingerprint(Task("k", tasks.fail, {"n": 4, "m": [1.5, 2]}), 1)


def test_a_tasks_arguments_cannot_change_after_it_is_made():
    given = {"n": 4}
    task = Task("k", tasks.draws, given)
    given["n"] = 5
    assert task.kwargs == {"n": 4}
    with pytest.raises(TypeError):
        task.kwargs["n"] = 6


def test_a_task_pickles_as_the_same_call():
    import pickle

    task = Task("k", tasks.draws, {"n": 4})
    again = pickle.loads(pickle.dumps(task))
    assert again == task and again.function is tasks.draws and fingerprint(again, 1) == \
        fingerprint(task, 1)
