"""The report's advisor entry: the fidelity advisor on every bundled scene.

:mod:`refsim.advisor` at each tolerance, one sweep task per scene
(:func:`refsim.report.tasks.advise_scene`). A quick run asks for fewer
tolerances, simulates 1 s of each scene and skips the costliest one
(:data:`ADVISOR_QUICK_SKIP`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from refsim.report.run import Run

#: The advisor's tolerances (m) and simulated duration (s; None: each
#: scene's own), quick and full. The quick report simulates 1 s of each
#: scene (its first impacts) and times each run once.
ADVISOR_TOLERANCES = ((1e-2, 1e-3), (1e-2, 3e-3, 1e-3))
ADVISOR_DURATION = (1.0, None)
ADVISOR_REPEATS = (1, 3)

#: Bundled scenes the quick report does not advise, and why (the full report
#: advises every scene): three bodies in contact need the finest steps at
#: 1 mm, the costliest advice by far (minutes, where the others take seconds).
ADVISOR_QUICK_SKIP = {"mixed.toml": "three bodies in contact, the costliest advice by far; "
                                    "the full report advises it"}


@dataclass(frozen=True)
class AdvisedScene:
    """The advisor on one bundled scene: ``advice``, one
    :meth:`refsim.advisor.records.Advice.as_dict` per tolerance; or
    ``refused``, the advisor's reason for not tuning the scene; or
    ``skipped``, why this run did not ask (:data:`ADVISOR_QUICK_SKIP`)."""

    scene: str
    advice: tuple = ()
    refused: str = ""
    skipped: str = ""


@dataclass(frozen=True)
class AdvisorRun:
    scenes: tuple               # AdvisedScene, one per bundled scene, by name
    tolerances: tuple           # m
    duration: float | None      # s simulated (None: each scene's own)
    repeats: int                # wall-time repeats of each candidate run


def advisor(run: Run):
    import tempfile

    from refsim.bundled import bundled_scenes
    from refsim.errors import SweepError
    from refsim.report.tasks import advise_scene
    from refsim.sweep import Task, run_sweep

    tolerances = run.size(*ADVISOR_TOLERANCES)
    duration = run.size(*ADVISOR_DURATION)
    repeats = run.size(*ADVISOR_REPEATS)
    every = [path.name for path in bundled_scenes()]
    skipped = ADVISOR_QUICK_SKIP if run.quick else {}
    names = [name for name in every if name not in skipped]
    with tempfile.TemporaryDirectory(prefix="refsim-advise-") as store:
        # each scene's runs are kept in a store of its own, which its
        # tolerances share (a run common to two tolerances is made once)
        tasks = [Task(f"advise-{name}", advise_scene,
                      {"scene": name, "tolerances": list(tolerances), "duration": duration,
                       "repeats": repeats, "store": str(Path(store) / Path(name).stem)})
                 for name in names]
        sweep = run_sweep(tasks, progress=False, seed=run.seed, **run.sweep_options())
    answers = {}
    for name, result in zip(names, sweep.results, strict=True):
        if result.status != "done":
            raise SweepError(f"advise {name}: {result.error}")
        answers[name] = result.value
    scenes = tuple(AdvisedScene(name, skipped=skipped[name]) if name in skipped
                   else AdvisedScene(name, tuple(answers[name].get("advice", ())),
                                     answers[name].get("refused", ""))
                   for name in every)
    return AdvisorRun(scenes, tuple(tolerances), duration, repeats)
