"""The report's replays: the viewer's demos written as replay pages.

C11, C12 and wall bounces beside pybullet and MuJoCo, each one task of
:func:`refsim.report.tasks.write_replay_demo` run through
:mod:`refsim.sweep` and written into the report's directory; a run without
that directory, or without the viewer extra or the engine, records why.
"""

from __future__ import annotations

from dataclasses import dataclass

from refsim.report.run import Run

#: Where the replays go, inside the report's directory.
REPLAY_FOLDER = "replays"

#: Each replay's size budget (bytes): viser's client (~0.8 MB) and a few
#: hundred frames, so that the report's directory stays a few MB.
REPORT_REPLAY_BYTES = 2_000_000

#: The replays the report shows: (name of :data:`refsim.report.tasks.DEMO_ENGINES`,
#: the seed claim it illustrates or "", its title).
REPLAYS = (
    ("c11-interpenetration", "C11",
     "C11: slow contact, the seed's velocity exchange beside the corrected impulse"),
    ("c12-spin", "C12", "C12: the spinning cube, the seed's rotation beside the corrected one"),
    ("wall-bounce-pybullet", "", "A wall bounce: refsim beside pybullet"),
    ("wall-bounce-mujoco", "", "A wall bounce: refsim beside MuJoCo"),
)


@dataclass(frozen=True)
class ReplayRecord:
    """One replay page: ``status`` "written" (``file`` relative to the
    report's directory, its size and frames), "unavailable" (``reason``: the
    viewer extra or the engine is missing) or "not written" (no output
    directory)."""

    name: str
    claim: str
    title: str
    status: str
    file: str = ""
    reason: str = ""
    bytes: int = 0
    frames: int = 0
    timeline_frames: int = 0
    stride: int = 0
    runs: tuple = ()


def replays(run: Run):
    from refsim.conformance.matrix import make_directory
    from refsim.errors import SweepError
    from refsim.report.tasks import write_replay_demo
    from refsim.sweep import Task, run_sweep

    if run.out_dir is None:
        return [ReplayRecord(name, claim, title, "not written",
                             reason="no output directory (refsim report writes them into its own)")
                for name, claim, title in REPLAYS]
    folder = make_directory(run.out_dir / REPLAY_FOLDER)
    tasks = [Task(f"replay-{name}", write_replay_demo,
                  {"name": name, "path": str(folder / f"{name}.html"),
                   "max_bytes": REPORT_REPLAY_BYTES}) for name, _, _ in REPLAYS]
    sweep = run_sweep(tasks, progress=False, seed=run.seed, **run.sweep_options())
    records = []
    for (name, claim, title), result in zip(REPLAYS, sweep.results, strict=True):
        if result.status != "done":
            raise SweepError(f"replay {name}: {result.error}")
        answer = result.value
        if "unavailable" in answer:
            records.append(ReplayRecord(name, claim, title, "unavailable",
                                        reason=answer["unavailable"]))
            continue
        w = answer["written"]
        records.append(ReplayRecord(name, claim, title, "written",
                                    file=f"{REPLAY_FOLDER}/{w['file']}", bytes=w["bytes"],
                                    frames=w["frames"], timeline_frames=w["timeline_frames"],
                                    stride=w["stride"], runs=tuple(w["runs"])))
    return records
