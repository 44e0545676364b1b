"""Shared fixtures for the example-based tests."""

from __future__ import annotations

import fcntl
import pickle
from pathlib import Path

import pytest
from refsim.oracles import OracleUnavailable

from refsim.report.entries.conformance import MATRIX_CASES as QUICK_REPORT_CASES
from refsim.report.run import REPORT_SEED

#: The conformance matrix every test of the session reads (the kit's tests
#: and the quick report's page): the quick report's cases and seed, so that
#: the report and the kit's tests share one run of the shipped engines.
MATRIX_CASES = QUICK_REPORT_CASES[0]
MATRIX_SEED = REPORT_SEED


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


def shared_directory(tmp_path_factory, worker_id) -> Path:
    """The session's temporary directory that every pytest-xdist worker
    sees (each worker's own basetemp is below it; without xdist, the
    session's basetemp)."""
    shared = tmp_path_factory.getbasetemp()
    return shared if worker_id == "master" else shared.parent


def once_per_session(shared: Path, name: str, build):
    """``build(directory)``'s value, computed by the first worker of the
    session to ask (under a file lock, the others waiting) and read back
    from a pickle by the rest: a session fixture of pytest-xdist is
    otherwise made again by every worker. ``directory`` (``shared/name``)
    holds whatever files ``build`` writes."""
    directory = shared / name
    value_file = shared / f"{name}.pickle"
    with open(shared / f"{name}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if not value_file.exists():            # written last: the build finished
            directory.mkdir(exist_ok=True)
            value = build(directory)
            value_file.write_bytes(pickle.dumps(value))
    return pickle.loads(value_file.read_bytes())


def shipped_matrix_in(shared: Path, run_matrix=None):
    """``(matrix, results, pages)``: every shipped engine through the
    conformance kit, ``MATRIX_CASES`` cases per set from ``MATRIX_SEED``,
    its pages written to the directory ``pages``; made once per session
    in the shared directory ``shared`` (:func:`once_per_session`).

    ``run_matrix`` measures it (default: the kit's). A caller that has
    patched the kit's with one that asks for this shared matrix passes the
    original: the patched one would ask again from inside the build, and
    wait for ever on the lock it holds."""
    if run_matrix is None:
        from refsim.conformance.matrix import run_matrix

    def build(directory):
        return run_matrix(cases=MATRIX_CASES, seed=MATRIX_SEED, out_dir=directory)

    matrix, results = once_per_session(shared, "shipped-matrix", build)
    return matrix, results, shared / "shipped-matrix"


@pytest.fixture(scope="session")
def shipped_matrix(tmp_path_factory, worker_id):
    """:func:`shipped_matrix_in` the session's shared directory."""
    return shipped_matrix_in(shared_directory(tmp_path_factory, worker_id))
