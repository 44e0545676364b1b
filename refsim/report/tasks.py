"""The report's sweep tasks: its measurements as calls that
:func:`refsim.sweep.run_sweep` can send to another process.

A sweep task is a module-level function taking ``seed`` and plain
arguments and returning plain data (:mod:`refsim.sweep.records`), so the
same call gives the same answer in this process, on local processes or on a
Dask cluster: ``refsim report --workers N`` changes where these run, never
what they return. The conformance matrix's task is
:func:`refsim.conformance.matrix.engine_task`; here are the others:

- :func:`write_replay_demo`: one replay of :mod:`refsim.viewer.demos`
  (claims C11 and C12, a wall bounce beside pybullet or MuJoCo) written into
  the report's directory;
- :func:`advise_scene`: the fidelity advisor
  (:func:`refsim.advisor.advice.advice_by_tolerance`) on one scene at each
  tolerance.

- :func:`measure_entry`: any other entry of the plan
  (:data:`refsim.report.plan.PARALLEL_ENTRIES`), measured in a fresh run in
  the worker. Its records are dataclasses of arrays made for the report's
  sections, not plain data: they travel pickled, as text (base64), and
  :func:`entry_records` turns them back. Pickle carries every float to the
  bit, and the report's sweeps have no store, so the plain-data rule's
  reason (a store another version reads) does not apply to them.

None uses the sweep's seed: the demos and the advisor are deterministic, and
an entry uses the report's seed (``report_seed``), as it does when measured
in the report's process. Cost: the demo's simulations and one replay
serialization; the advice's runs; the entry's measurement and one pickle.
"""

from __future__ import annotations

import base64
import pickle
from pathlib import Path
from typing import Any

#: The demos :func:`write_replay_demo` knows, by name: the engine of
#: :data:`refsim.engines.registry.ENGINES` it runs beside refsim, or None
#: (refsim's seed model beside its corrected one).
DEMO_ENGINES = {"c12-spin": None, "c11-interpenetration": None,
                "wall-bounce-pybullet": "pybullet", "wall-bounce-mujoco": "mujoco"}


def write_replay_demo(*, seed: int, name: str, path: str, max_bytes: int) -> dict:
    """Write the demo ``name`` (:data:`DEMO_ENGINES`) to ``path``.

    Returns ``{"written": ReplayInfo's numbers}``, or ``{"unavailable":
    reason}`` when viser (the ``viewer`` extra) or the engine beside refsim
    is not installed: checked before any simulation runs.
    """
    from refsim.oracles import OracleUnavailable
    from refsim.viewer.demos import demo_c11, demo_c12, demo_wall_bounce
    from refsim.viewer.server import ViewerUnavailable, require_viser

    if name not in DEMO_ENGINES:
        raise ValueError(f"no replay demo {name!r} (demos: {', '.join(DEMO_ENGINES)})")
    try:
        require_viser()
        engine = DEMO_ENGINES[name]
        if engine is not None:
            info = demo_wall_bounce(path, engine=engine, max_bytes=max_bytes)
        elif name == "c12-spin":
            info = demo_c12(path, max_bytes=max_bytes)
        else:
            info = demo_c11(path, max_bytes=max_bytes)
    except (ViewerUnavailable, OracleUnavailable) as exc:
        return {"unavailable": str(exc)}
    return {"written": {"bytes": info.bytes, "stride": info.stride, "frames": info.frames,
                        "timeline_frames": info.timeline_frames, "runs": list(info.runs),
                        "file": Path(path).name}}


def advise_scene(*, seed: int, scene: str, tolerances: list, duration: float | None,
                 repeats: int, store: str | None,
                 max_reference_steps: int | None = None) -> dict:
    """The advisor's answer for ``scene`` (a bundled name or a path) at each
    tolerance, in this process, each tolerance sharing the runs of the
    others through ``store``.

    Returns ``{"advice": [Advice.as_dict(), ...]}`` in the order of
    ``tolerances``, or ``{"refused": message}`` for a scene the advisor does
    not tune (a particle scene: its StateError, one line).
    """
    from refsim.advisor.advice import advice_by_tolerance
    from refsim.advisor.reference import MAX_REFERENCE_STEPS
    from refsim.errors import StateError

    try:
        (series,) = advice_by_tolerance(
            scenes=(scene,), tolerances=tuple(tolerances), store=store, duration=duration,
            repeats=repeats,
            max_reference_steps=max_reference_steps or MAX_REFERENCE_STEPS)
    except StateError as exc:
        return {"refused": str(exc)}
    return {"advice": [advice.as_dict() for advice in series.advice]}


def measure_entry(*, seed: int, name: str, quick: bool, report_seed: int) -> dict:
    """The records of the plan's entry ``name`` measured in a fresh
    :class:`refsim.report.run.Run` (quick or full, ``report_seed``), in
    this process: ``{"records": <pickle as base64 text>, "missing": {engine:
    why}}`` (the engines it could not make). An entry whose records hold
    timing fields is refused: it must run alone (``Study.timed``), and this
    check keeps that flag true."""
    from refsim.errors import SweepError
    from refsim.report.run import Run
    from refsim.report.section import to_json

    run = Run(quick=quick, seed=report_seed)
    records = run.get(name)
    timings: set = set()
    to_json(records, (), timings)
    if timings:      # measured beside other work: its timings would be disturbed
        raise SweepError(f"entry {name!r} holds timings ({sorted(timings)[0]}, ...): "
                         "mark its Study timed=True so that the report measures it alone")
    text = base64.b64encode(pickle.dumps(records, protocol=pickle.HIGHEST_PROTOCOL))
    return {"records": text.decode("ascii"), "missing": dict(run.missing)}


def entry_records(value: dict) -> tuple[Any, dict]:
    """``(records, missing)`` of a :func:`measure_entry` answer."""
    return pickle.loads(base64.b64decode(value["records"])), dict(value["missing"])
