"""The steps the advisor tries and the runs it has made.

:class:`Ladder` is the grid of steps, each a whole number of steps per
sample interval; :class:`Setting` is one point of the search on it (solver,
step, collision level, box update). :class:`Runner` keeps every run made so
far by setting, with the roles it was made for, and makes the missing ones
in one :func:`refsim.sweep.run_sweep` call per round: in-process, on local
processes or on a Dask cluster, with the same results on each. With a
``store``, every finished run is kept on disk, so that an interrupted advice
resumes and advice at another tolerance reuses the runs it shares (a run's
key names its settings and the scene's content, not TOL).
"""

from __future__ import annotations

import sys
import time
from dataclasses import dataclass
from fractions import Fraction

from refsim.advisor import metrics
from refsim.advisor.records import Fidelity
from refsim.advisor.runs import measure_run, scene_data
from refsim.errors import SweepError
from refsim.scenes.schema import Scene
from refsim.solvers.integrate import whole_steps
from refsim.solvers.methods import SOLVERS
from refsim.sweep.records import canonical, digest
from refsim.sweep.run import run_sweep
from refsim.sweep.tasks import Task

#: The longest step considered and the spacing of the common sample times
#: (s): 10 ms, in which a body at the bundled scenes' impact speeds (a few
#: m/s) moves centimetres, more than any tolerance of interest. The actual
#: interval is the largest whole number of the scene's steps not above it
#: that divides the run, so that the scene's own step is among the steps tried.
SAMPLE_INTERVAL = 0.01

#: Wall-time repeats of each candidate run (the median is reported); the
#: reference's halvings are timed once (they are not candidates but for
#: the check).
TIMING_REPEATS = 3


@dataclass(frozen=True)
class Ladder:
    """The steps the advisor tries: ``interval / m`` for whole ``m`` >= 1,
    where ``interval`` is ``divisions`` of the scene's own steps (so the
    scene's step is ``m = divisions``) and divides the run into ``samples``
    sample intervals. Every step on it is a whole number of steps per sample
    and per run. Steps are computed in exact fractions of the scene's step,
    so ``step(divisions)`` is the scene's step to the bit."""

    scene_step: float
    divisions: int
    samples: int

    @classmethod
    def for_scene(cls, step: float, duration: float) -> Ladder:
        n = whole_steps(duration, step)
        most = max(1, int(SAMPLE_INTERVAL / step * (1.0 + 1e-9)))
        divisions = max(k for k in range(1, min(most, n) + 1) if n % k == 0)
        return cls(step, divisions, n // divisions)

    @property
    def interval(self) -> float:
        return float(Fraction(self.scene_step) * self.divisions)

    def step(self, m: int) -> float:
        return float(Fraction(self.scene_step) * self.divisions / m)

    def n_steps(self, m: int) -> int:
        return self.samples * m


@dataclass(frozen=True, order=True)
class Setting:
    """A point of the search: solver, ``m`` on the ladder, level, box update."""

    solver: str
    m: int
    level: str
    aabb: str

    def fidelity(self, ladder: Ladder) -> Fidelity:
        return Fidelity(self.solver, ladder.step(self.m), self.level, self.aabb)

    def force_evaluations(self, ladder: Ladder, bodies: int) -> int:
        """Known before the run: steps x stages x bodies (a lower bound of the proxy)."""
        return ladder.n_steps(self.m) * SOLVERS[self.solver].stages * bodies


class Runner:
    """The runs made so far, by setting; :meth:`run` makes the missing ones
    through one :func:`run_sweep` call (state: the runs, their roles)."""

    def __init__(self, scene: Scene, ladder: Ladder, *, duration: float, backend: str,
                 workers, scheduler, store, progress: bool, repeats: int):
        # every run replaces [integration] and [collision] (measure_run): left
        # out, so that a run's key and fingerprint depend on the physics alone
        data = scene_data(scene)
        self.data = {k: v for k, v in data.items() if k not in ("integration", "collision")}
        self.name = digest(canonical(self.data))[:12]      # the scene's content, in each key
        self.ladder = ladder
        self.duration = duration
        self.options = dict(backend=backend, workers=workers, scheduler=scheduler, store=store,
                            progress=progress)
        self.repeats = repeats
        self.runs: dict[Setting, metrics.Run] = {}
        self.roles: dict[Setting, list[str]] = {}
        self.computed = 0
        self.resumed = 0
        self.progress = progress
        self._started = self._said = time.monotonic()

    def run(self, wanted: list[tuple[Setting, str]], *, once=()) -> None:
        """Make the runs of ``wanted`` not made yet, timed ``repeats`` times
        (those in ``once``: once); note each one's role."""
        tasks, settings = [], []
        for setting, role in wanted:
            roles = self.roles.setdefault(setting, [])
            if role not in roles:
                roles.append(role)
            if setting in self.runs or setting in settings:
                continue
            repeats = 1 if setting in once else self.repeats
            fidelity = setting.fidelity(self.ladder)
            key = f"{self.name} {fidelity.label()} T={self.duration!r} x{repeats}"
            tasks.append(Task(key, measure_run, dict(
                scene=self.data, solver=setting.solver, step=fidelity.step,
                level=setting.level, aabb=setting.aabb, duration=self.duration,
                every=setting.m, repeats=repeats)))
            settings.append(setting)
        if not tasks:
            return
        result = run_sweep(tasks, **self.options)
        if not result.ok:
            key, reason = next(iter(result.failures.items()))
            raise SweepError(f"run {key.split(' ', 1)[1]!r} failed: {reason}")
        for setting, task_result in zip(settings, result.results, strict=True):
            self.runs[setting] = metrics.Run.from_record(task_result.value)
            self.resumed += task_result.resumed
            self.computed += not task_result.resumed
        self._say_progress()

    def _say_progress(self) -> None:
        """With progress on: a line on stderr after a round of runs, at most
        every ``LOG_SECONDS`` (and not in the first ones), with the runs made
        so far: each round's sweep shows only its own runs, and an advice
        takes many rounds."""
        from refsim.sweep.progress import LOG_SECONDS

        now = time.monotonic()
        if not self.progress or now - self._said < LOG_SECONDS:
            return
        self._said = now
        minutes, seconds = divmod(int(now - self._started), 60)
        print(f"advise: {self.computed + self.resumed} runs so far ({self.resumed} from the "
              f"store), {minutes}:{seconds:02d} elapsed", file=sys.stderr, flush=True)
