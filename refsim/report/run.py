"""A run of the report's plan: its records, engines and verdicts, and the
scheduler that measures entries beside each other on local processes.

A :class:`Run` measures each entry of :data:`refsim.report.plan.STUDIES`
once, makes each engine it is asked for once (by its name in
:data:`refsim.engines.registry.ENGINES`), and
judges each seed claim from the records of the entry that backs it
(:data:`refsim.report.plan.CLAIM_STUDY`). A :class:`Study` is one entry of
that table. The plan imports this module to build its table, so a run reads
the table from the plan inside the methods that use it (an import at the
top would be circular).

With ``workers``, :meth:`Run.prefetch` sends the entries that may run
elsewhere (:data:`refsim.report.plan.SWEEP_ENTRIES` and
:data:`~refsim.report.plan.PARALLEL_ENTRIES`) to that many local processes
from a background thread, while this thread measures the others; the timed
entries wait for the workers to finish, so that they are measured on an
otherwise idle machine. The records are the same either way.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from concurrent.futures import Future, wait
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from refsim.claims.result import ClaimResult

#: The seed every random choice in the report derives from, and the default
#: seed of ``refsim study``, so that the command printed under a figure
#: reproduces the figure as it is.
REPORT_SEED = 0


class Run:
    """One run of the plan: quick or full sizes, a seed, and the records and
    engines made so far (each entry is measured once per run, each engine
    made once).

    ``announce(text)`` is told what is being measured before each entry.
    """

    def __init__(self, *, quick: bool = False, seed: int = REPORT_SEED,
                 announce: Callable[[str], None] | None = None, out_dir=None,
                 workers: int | None = None):
        self.quick = quick
        self.seed = seed
        #: Where entries that write pages put them (the report's directory);
        #: None: such entries write nothing and say so.
        self.out_dir = None if out_dir is None else Path(out_dir)
        #: Local processes for the entries that run through refsim.sweep
        #: (None: in this process); their records are the same either way.
        self.workers = workers
        self.missing: dict[str, str] = {}     # engine name -> why it is unavailable
        self._announce = announce or (lambda text: None)
        self._records: dict[str, Any] = {}
        self._engines: dict[str, Any] = {}
        self._claims: dict[str, ClaimResult] = {}
        self._pending: dict[str, Future] = {}    # entries measured beside this thread
        self._cancel = threading.Event()         # stops the sweeps of that thread
        self._thread: threading.Thread | None = None

    def size(self, quick, full):
        """``quick`` in a quick run, ``full`` otherwise."""
        return quick if self.quick else full

    def sweep_options(self) -> dict:
        """``backend`` and ``workers`` for :func:`refsim.sweep.run_sweep`:
        local processes when the run was given workers, else this process."""
        if self.workers is None:
            return {"backend": "inprocess", "workers": None}
        return {"backend": "processes", "workers": self.workers, "cancel": self._cancel}

    def cancel(self, timeout: float = 30.0) -> None:
        """Stop the sweeps started by :meth:`prefetch` (their workers are
        terminated) and wait up to ``timeout`` seconds for them to stop: a
        report interrupted in this thread must not wait for the workers'
        tasks to end."""
        self._cancel.set()
        if self._thread is not None:
            self._thread.join(timeout)

    def prefetch(self, names) -> None:
        """Start measuring, in a background thread, the entries among
        ``names`` that run on the workers: first the
        :data:`~refsim.report.plan.PARALLEL_ENTRIES` in one sweep (a task
        each, in a fresh :class:`Run` in the worker), then the
        :data:`~refsim.report.plan.SWEEP_ENTRIES` one after
        the other (each its own sweep). The workers stay busy while this
        thread measures what must run here; :meth:`get` waits for an entry's
        records, and a timed entry waits for all of them, so that it is
        measured on an otherwise idle machine. Only with workers: the thread
        spends its time waiting for the workers' answers, and the records
        are the same as measured in order. (An entry measured here must
        touch nothing of the run but its settings: these make no engine here
        and read no other entry.)"""
        from refsim.report.plan import PARALLEL_ENTRIES, STUDIES, SWEEP_ENTRIES

        wanted = [n for n in names if (n in SWEEP_ENTRIES or n in PARALLEL_ENTRIES)
                  and n not in self._records and n not in self._pending]
        if self.workers is None or not wanted:
            return
        futures: dict[str, Future] = {name: Future() for name in wanted}
        self._pending.update(futures)
        parallel = {n: futures[n] for n in wanted if n in PARALLEL_ENTRIES}

        def measure() -> None:
            if parallel:
                self._measure_parallel(parallel)
            for name, future in futures.items():
                if name in parallel or not future.set_running_or_notify_cancel():
                    continue
                try:
                    future.set_result((STUDIES[name].measure(self), {}))
                except BaseException as exc:  # noqa: BLE001 - handed to get() in the main thread
                    future.set_exception(exc)

        # a daemon thread: Ctrl-C in the main thread is not held up by it (and
        # cancel() stops its sweeps)
        self._thread = threading.Thread(target=measure, name="refsim-report-sweeps",
                                        daemon=True)
        self._thread.start()

    def _measure_parallel(self, futures: dict[str, Future]) -> None:
        """The entries of ``futures`` as one sweep on the workers; each
        future gets ``(records, engines missing in the worker)``."""
        from refsim.errors import SweepError
        from refsim.report.tasks import entry_records, measure_entry
        from refsim.sweep import Task, run_sweep

        tasks = [Task(f"entry-{name}", measure_entry,
                      {"name": name, "quick": self.quick, "report_seed": self.seed})
                 for name in futures]
        try:
            sweep = run_sweep(tasks, progress=False, seed=self.seed, **self.sweep_options())
        except BaseException as exc:  # noqa: BLE001 - handed to get() in the main thread
            for future in futures.values():
                future.set_exception(exc)
            return
        for (name, future), result in zip(futures.items(), sweep.results, strict=True):
            if result.status != "done":
                future.set_exception(SweepError(f"{name}: {result.error}"))
            else:
                future.set_result(entry_records(result.value))

    def get(self, name: str):
        """The records of entry ``name`` (measured on first use)."""
        from refsim.report.plan import STUDIES

        if name not in self._records and name in self._pending:
            records, missing = self._pending.pop(name).result()
            for engine, why in missing.items():
                self.missing.setdefault(engine, why)
            self._records[name] = records
        if name not in self._records:
            study = STUDIES[name]
            if study.timed and self._pending:
                wait(list(self._pending.values()))   # time it on an idle machine
            self._announce(study.title)
            self._records[name] = study.measure(self)
        return self._records[name]

    def engine(self, name: str):
        """The engine ``name`` of :data:`refsim.engines.registry.ENGINES`,
        made once per run and shared by the entries (one pybullet client
        serves every bounce scene; each ``simulate`` resets it); raises
        :class:`refsim.oracles.OracleUnavailable` when it is missing."""
        from refsim.engines import registry
        from refsim.oracles import OracleUnavailable

        if name not in self._engines:
            try:
                self._engines[name] = registry.build(name)
            except OracleUnavailable as exc:
                self._engines[name] = None
                self.missing[name] = str(exc)
        if self._engines[name] is None:
            raise OracleUnavailable(self.missing[name])
        return self._engines[name]

    def optional(self, name: str):
        """The oracle engine ``name``, or None when it is missing (the reason
        is in :attr:`missing`)."""
        from refsim.oracles import OracleUnavailable

        try:
            return self.engine(name)
        except OracleUnavailable:
            return None

    def claim(self, claim: str) -> ClaimResult:
        """The verdict on seed claim ``claim``, judged from the records of the
        entry that backs it."""
        from refsim.report.plan import CLAIM_STUDY, STUDIES

        if claim not in self._claims:
            name = CLAIM_STUDY[claim]
            self._claims[claim] = STUDIES[name].claims[claim](self.get(name))
        return self._claims[claim]


@dataclass(frozen=True)
class Study:
    """One named study run: ``measure(run)`` returns its records."""

    name: str
    title: str                  # what the progress line says while it runs
    measure: Callable[[Run], Any]
    # seed claim -> judge(records) -> ClaimResult, for the claims it backs
    claims: dict[str, Callable[[Any], ClaimResult]] = field(default_factory=dict)
    in_report: bool = True      # False: offered by ``refsim study`` only
    #: Its records hold wall times (timing fields): with workers, it is
    #: measured in the report's process after the workers are done, on an
    #: otherwise idle machine, never beside them.
    timed: bool = False
    #: It gathers other entries' records (``run.get``): measured in the
    #: report's process, from the records the others returned.
    gathers: bool = False

