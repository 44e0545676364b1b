"""The ``refsim`` command line.

    refsim info MODEL                  facts about a model file
    refsim info --bundled              the bundled models and scenes, by name
    refsim run SCENE [-o OUT.npz] [--every K]
                                       simulate a scene (bodies or particles), write frames
    refsim report [--quick | --full] [-o DIR] [--workers N]
                                       write the HTML accuracy report
    refsim study NAME [--quick] [--seed S]
                                       run one of the report's studies, print its
                                       records and the verdicts they back
    refsim view SCENE [--port N]       the scene in the browser, re-run from its controls
    refsim replay RUN.npz ... -o OUT.html
                                       recorded runs as one standalone replay page
    refsim advise SCENE [--tolerance TOL] [-o DIR] [--json]
                                       the cheapest fidelity settings within TOL

A user's mistake (a missing or malformed file, a bad scene) prints one line
naming the file and the line or key, and exits with status 2; ``--debug``
shows the traceback instead. A run that diverges prints one line naming the
step and time, writes the frames computed before it, and exits with status 3.
Anything else is a bug in refsim and keeps its traceback. Output files are
written whole or not at all (a temporary file, then ``os.replace``). Output
cut short by its reader (``refsim info X | head -1``) ends quietly with
status 1. ``refsim --version`` prints the installed version.
"""

from __future__ import annotations

import argparse
import contextlib
import gc
import json
import os
import sys
import warnings
from dataclasses import asdict
from pathlib import Path

from refsim.errors import DivergenceError, OutputError, RefsimError, SceneError
from refsim.kernels import TIERED_ENV, compile_notices, notices_on
from refsim.signals import Interrupted, signals_raise

EXIT_USER_ERROR = 2
EXIT_DIVERGED = 3

#: The status of a command whose reader went away (``refsim info X | head -1``):
#: not a success, since the output was cut short, yet nothing to report.
EXIT_BROKEN_PIPE = 1

#: The suffixes of the files refsim's commands write. An output directory
#: named with one of them is a file name given where a directory is meant
#: (``refsim report -o report.html``), refused rather than made a directory.
FILE_SUFFIXES = (".npz", ".html", ".htm", ".json", ".svg", ".toml", ".txt")


def _output_file(path, suffixes: tuple[str, ...], command: str) -> Path:
    """``path`` as a Path when it can be written (:func:`refsim.storage.writing.output_target`:
    not a directory, device or FIFO, in a directory that exists) and its
    suffix is one of ``suffixes`` (in any case): the command writes that
    format whatever the name says, so another suffix is refused
    (OutputError naming the path) before any work."""
    from refsim.storage.writing import output_error, output_target

    out = Path(path)
    output_target(out)
    if out.suffix.lower() not in suffixes:
        raise output_error(out, f"refsim {command} writes {' or '.join(suffixes)} files; "
                                f"name the output with the suffix {suffixes[0]}")
    return out


def _output_directory(path, command: str, writes: str) -> Path:
    """``path`` as a Path for a command that writes a directory (``writes``
    says what goes in it); a name with a file's suffix (FILE_SUFFIXES) that
    is not already a directory is refused before any work."""
    from refsim.storage.writing import output_error

    out = Path(path)
    if out.suffix.lower() in FILE_SUFFIXES and not out.is_dir():
        raise output_error(out, f"refsim {command} writes a directory ({writes}), not a "
                                f"{out.suffix} file; name a directory")
    return out


def _info(args) -> int:
    from refsim.errors import OptionError
    from refsim.models.facts import describe, format_facts
    from refsim.models.loading import load_model

    if args.bundled:
        if args.models:
            raise OptionError("--bundled lists the bundled models and scenes; give it "
                              "without MODEL files")
        from refsim.bundled import bundled_models, bundled_scenes

        for path in (*bundled_models(), *bundled_scenes()):
            print(path.name)
        return 0
    if not args.models:
        raise OptionError("give one or more MODEL files, or --bundled to list the bundled "
                          "models and scenes (see refsim info --help)")
    for i, path in enumerate(args.models):
        if i:
            print()
        print(format_facts(describe(load_model(path), name=str(path))))
    return 0


def _settings(scene, every: int) -> dict:
    """The scene's settings as written into the .npz (entry ``scene``, JSON)."""
    from refsim import __version__

    return {
        "scene": None if scene.path is None else str(scene.path),
        "world": asdict(scene.world),
        "integration": asdict(scene.integration),
        "particles": asdict(scene.particles),
        "every": every,
        "refsim": __version__,
    }


def _run(args) -> int:
    from refsim.scenes.loader import load_scene_text

    if args.output:
        _output_file(args.output, (".npz",), "run")
    max_steps = _max_steps(args)
    scene, text = load_scene_text(args.scene, max_steps=max_steps)
    if args.duration is not None:
        scene = _with_duration(scene, args.duration, max_steps)
    if scene.bodies and scene.particles is not None:
        raise SceneError("refsim run simulates either rigid bodies or particles; this scene "
                         "has both (split it in two)", scene.path, "particles")
    if args.every is not None and args.every < 1:
        raise RefsimError(f"--every must be at least 1, got {args.every}")
    out = Path(args.output) if args.output else Path(Path(args.scene).stem + ".npz")
    if not out.parent.is_dir():
        raise RefsimError(f"{out}: cannot write: no directory {out.parent}")
    if scene.bodies:
        return _run_bodies(scene, text, out, args.every)
    return _run_particles(scene, out, args.every)


def _max_steps(args) -> int:
    """``--max-steps``, checked, or the scenes' default limit."""
    from refsim.errors import check_count
    from refsim.limits import DEFAULT_MAX_STEPS, MAX_STEPS

    if args.max_steps is None:
        return DEFAULT_MAX_STEPS
    return check_count("--max-steps", args.max_steps, 1, MAX_STEPS)


def _with_duration(scene, duration: float, max_steps: int | None = None):
    """``scene`` simulated for ``duration`` seconds instead of its own, in
    at most ``max_steps`` steps (default: the scenes' limit)."""
    from dataclasses import replace

    from refsim.errors import StateError
    from refsim.limits import DEFAULT_MAX_STEPS
    from refsim.scenes.loader import steps_limit_hint
    from refsim.solvers.integrate import whole_steps

    max_steps = DEFAULT_MAX_STEPS if max_steps is None else max_steps
    try:
        whole_steps(duration, scene.integration.step, max_steps)
    except StateError as exc:
        if not 0.0 < duration < scene.integration.step:   # the option's own fault
            hint = steps_limit_hint(duration, scene.integration.step, max_steps)
            raise RefsimError(f"--duration {duration!r}: {exc}{hint}") from None
        # no whole step fits: the option against the scene's step, both named
        raise SceneError(f"the step {scene.integration.step:g} is longer than --duration "
                         f"{duration!r}: no whole step fits", scene.path,
                         "integration.step") from None
    return replace(scene, integration=replace(scene.integration, duration=duration))


def _write(out: Path, save) -> None:
    """``save(out)``; an ``OSError`` (a full disk, a refused target) becomes
    an :class:`OutputError` naming ``out`` (refsim.storage.writing leaves no file)."""
    from refsim.storage.writing import output_error

    try:
        save(out)
    except OutputError:
        raise
    except OSError as exc:
        raise output_error(out, exc.strerror or str(exc)) from exc


#: ``refsim run`` shows its progress line only once it has run this long (s):
#: a short run prints its one closing line and nothing else.
RUN_PROGRESS_DELAY = 2.0


@contextlib.contextmanager
def _frame_progress(n_steps: int, every: int, sink):
    """``sink`` wrapped so that a long run shows its frames so far on stderr
    (redrawn on a terminal after ``RUN_PROGRESS_DELAY``; elsewhere a line
    every ten seconds once it has run that long: never silent)."""
    from refsim.storage.frames import CountedSink, frame_count
    from refsim.sweep.progress import Progress

    progress = Progress(frame_count(n_steps, every), label="refsim run", unit="frames",
                        delay=RUN_PROGRESS_DELAY)
    try:
        yield CountedSink(sink, progress)
    finally:
        progress.close()


def _run_bodies(scene, text: str, out: Path, every: int | None) -> int:
    """Rigid bodies: ``refsim.simulate`` with the frames spilled beside
    ``out`` as they are computed (:class:`refsim.storage.frames.SpillSink`: memory
    does not grow with the steps), then written as a Trajectory (.npz) whose
    settings record the scene: its file and its ``text``, from which
    ``refsim replay`` rebuilds the meshes."""
    from refsim.dynamics.simulate import default_every, simulate
    from refsim.dynamics.start import start_kernel
    from refsim.storage.frames import SpillSink, check_disk_space
    from refsim.storage.writing import output_target
    from refsim.viewer.replay import recorded_scene_settings

    output_target(out)                  # a FIFO, device or directory: refused before running
    B = len(scene.bodies)
    n_steps = scene.integration.n_steps
    # t, then position, velocity, angular_velocity (B, 3) and orientation (B, 3, 3)
    check_disk_space(out, [8, 24 * B, 24 * B, 24 * B, 72 * B], n_steps,
                     default_every(n_steps) if every is None else every, compressed=True,
                     frames_of=f"{B} {'body' if B == 1 else 'bodies'}",
                     size_hint=f"{scene.path}: fewer [[body]] tables")
    kernel = start_kernel(scene, n_steps)
    if kernel is not None and notices_on():
        print("refsim: numba has not compiled the simulation loop on this machine yet; "
              "this run takes less on the readable kernels than the compile would "
              "(the same results, bit for bit)", file=sys.stderr, flush=True)
    every = default_every(n_steps) if every is None else every
    with SpillSink(out) as spill, _frame_progress(n_steps, every, spill) as sink:
        try:
            trajectory = simulate(scene, every=every, sink=sink, kernel=kernel)
        except DivergenceError as exc:
            partial = exc.partial
            partial.settings.update(recorded_scene_settings(scene.path, text))
            _write(out, partial.save)
            raise DivergenceError(
                f"{exc.message}; wrote the {partial.n_frames} frames before "
                f"it (t = 0 to {partial.t[-1]:.6g}) to {out}", step=exc.step, time=exc.time,
                body=exc.body) from None
        trajectory.settings.update(recorded_scene_settings(scene.path, text))
        _write(out, trajectory.save)
        n_frames, t_end = trajectory.n_frames, float(trajectory.t[-1])
    ran = ", ".join(trajectory.stages)
    print(f"wrote {out}: {n_frames} frames of {B} {'body' if B == 1 else 'bodies'}, "
          f"t = 0 to {t_end:.6g} ({scene.integration.solver}, "
          f"h = {scene.integration.step:g}); stages: {ran}")
    return 0


def _run_particles(scene, out: Path, every: int | None) -> int:
    """Particles: :func:`refsim.particles.run.run_particles` with the frames
    spilled beside ``out`` as they are computed, then written as .npz
    (uncompressed: random floats do not compress, and it is faster)."""
    import numpy as np

    from refsim.particles.run import FRAME_BYTES_PER_PARTICLE, frame_stride, run_particles
    from refsim.storage.frames import SpillSink, check_disk_space
    from refsim.storage.writing import output_target, write_npz_atomic

    output_target(out)                  # a FIFO, device or directory: refused before running
    config = scene.particles
    n_steps, every = frame_stride(scene, every)
    N = config.count
    # t, step, then position and velocity (N, 3)
    check_disk_space(out, [8, 8, FRAME_BYTES_PER_PARTICLE // 2 * N,
                           FRAME_BYTES_PER_PARTICLE // 2 * N], n_steps, every,
                     compressed=False, frames_of=f"{N} particles",
                     size_hint=f"{scene.path}: particles.count")

    def save(frames, status: str):
        arrays = {"t": frames.t, "step": frames.step, "position": frames.position,
                  "velocity": frames.velocity,
                  "scene": np.array(json.dumps(_settings(scene, every), sort_keys=True)),
                  "status": np.array(status)}
        _write(out, lambda path: write_npz_atomic(path, arrays))

    with SpillSink(out) as spill, _frame_progress(n_steps, every, spill) as sink:
        try:
            frames = run_particles(config, n_steps, every, sink=sink)
        except DivergenceError as exc:
            partial = exc.partial
            assert partial is not None, "run_particles keeps the frames before a divergence"
            save(partial, f"diverged at step {exc.step}, t = {exc.time:.6g}")
            raise DivergenceError(
                f"particle state is not finite; wrote the {len(partial.t)} frames before it "
                f"(t = 0 to {partial.t[-1]:.6g}) to {out}", step=exc.step,
                time=exc.time) from None
        save(frames, "complete")
        n_frames, t_end = len(frames.t), float(frames.t[-1])
    print(f"wrote {out}: {n_frames} frames of {config.count} particles, "
          f"t = 0 to {t_end:.6g} ({config.solver}, h = {config.step:g}, "
          f"every {every} steps)")
    return 0


def _report(args) -> int:
    from refsim.errors import check_count
    from refsim.report import require_report

    require_report()        # before any work: the charts import matplotlib when drawn
    from refsim.report.build import build_report

    out = _output_directory(args.output, "report", "index.html, results.json and the pages "
                                                   "they link")
    workers = None if args.workers is None else check_count("--workers", args.workers, 1)
    try:
        page = build_report(out, quick=not args.full, workers=workers)
    except OSError as exc:
        raise RefsimError(f"{out}: cannot write the report: {exc.strerror or exc}") from exc
    print(f"wrote {page}")
    return 0


def _view(args) -> int:
    from refsim.scenes.loader import load_scene
    from refsim.viewer.live import serve
    from refsim.viewer.server import check_port, require_viser

    require_viser()
    check_port(args.port)
    scene = load_scene(args.scene, max_steps=_max_steps(args))
    serve(scene, host=args.host, port=args.port)   # until Ctrl-C
    return 0


def _replay(args) -> int:
    from refsim.viewer.replay import load_runs, write_replay
    from refsim.viewer.server import require_viser

    _output_file(args.output, (".html", ".htm"), "replay")
    require_viser()
    runs = load_runs(args.runs, scenes=args.scene or ())
    info = write_replay(runs, args.output, overlay=args.overlay, max_bytes=args.max_bytes,
                        boxes=args.boxes)
    print(info.summary())
    return 0


def _study(args) -> int:
    """Run one entry of the report's plan and print its records, then the
    verdicts on the seed claims it backs (each with its facts)."""
    from refsim.errors import check_count
    from refsim.oracles import OracleUnavailable
    from refsim.report.plan import STUDIES
    from refsim.report.run import Run
    from refsim.report.text import TIMING_NOTE, format_claim, format_records

    workers = None if args.workers is None else check_count("--workers", args.workers, 1)
    out = None
    if args.output is not None:
        from refsim.conformance.matrix import make_directory

        out = make_directory(_output_directory(args.output, "study", "the pages of the "
                                                                     "studies that write them"))
    run = Run(quick=args.quick, seed=args.seed, out_dir=out, workers=workers,
              announce=lambda text: print(f"refsim: measuring {text}", file=sys.stderr))
    try:
        records = run.get(args.name)
    except OracleUnavailable as exc:
        raise RefsimError(f"study {args.name}: {exc}") from None
    print(format_records(records))
    for claim in STUDIES[args.name].claims:
        print()
        print(format_claim(run.claim(claim)))
    print()
    print(TIMING_NOTE)
    for engine, why in run.missing.items():
        print(f"refsim: note: {engine} is missing, its columns are empty: {why}",
              file=sys.stderr)
    return 0


def _add_study_command(commands) -> None:
    """``refsim study NAME``: the command each figure of the report names."""
    from refsim.report.plan import STUDIES
    from refsim.report.run import REPORT_SEED

    study = commands.add_parser(
        "study", help="run one of the report's studies and print its records",
        description="Run the study NAME exactly as the report runs it (the same engines "
                    "and sizes; --quick as the quick report) and print its records as "
                    "plain-text tables, then the verdicts on the seed claims it backs. "
                    "Every figure of the report names the command that reproduces it.")
    study.add_argument("name", metavar="NAME", choices=sorted(STUDIES),
                       help="one of: " + ", ".join(sorted(STUDIES)))
    study.add_argument("--quick", action="store_true",
                       help="the quick report's sizes (fewer sizes and repeats)")
    study.add_argument("--seed", type=int, default=REPORT_SEED, metavar="S",
                       help=f"seed of the random choices (default {REPORT_SEED}, the report's)")
    study.add_argument("-o", "--output", metavar="DIR",
                       help="where studies that write pages put them (the conformance "
                            "pages, the replays); created if missing (default: none written)")
    study.add_argument("--workers", type=int, metavar="N",
                       help="run the studies that go through refsim.sweep (conformance-matrix, "
                            "replays, advisor) on N local processes")
    study.set_defaults(run=_study)


EXIT_CHECK_FAILED = 1


def _conform(args) -> int:
    """``refsim conform``: one engine through the conformance kit, or the
    shipped engines side by side (``--all``). Exit 0 when every check passed
    (declared expected failures aside), 1 when one failed; user errors
    (a bad spec, a missing engine, a malformed expected-failures file) are
    RefsimErrors and exit 2 (``main``)."""
    from refsim.conformance.expected import read_expected
    from refsim.conformance.matrix import make_directory, run_matrix, write_engine_pages
    from refsim.conformance.results import summary_table
    from refsim.conformance.runner import DEFAULT_CASES, check_engine, select_capabilities
    from refsim.engines import CAPABILITIES, load_engine
    from refsim.errors import OptionError, check_count
    from refsim.oracles import OracleUnavailable

    if (args.engine is None) == (not args.all):
        raise OptionError("give one engine as MODULE:FACTORY, or --all for the shipped ones")
    if args.all and args.expected_failures:
        raise OptionError("--expected-failures is for one engine; --all uses each shipped "
                          "engine's own file (refsim/conformance/expected/)")
    cases = check_count("--cases", DEFAULT_CASES if args.cases is None else args.cases, 1)
    seed = check_count("--seed", args.seed, minimum=0)
    out = _output_directory(args.output, "conform", "its JSON record and pages")
    if args.only is not None and args.only not in CAPABILITIES:
        raise OptionError(f"--only {args.only!r}: not a capability (capabilities: "
                          f"{', '.join(CAPABILITIES)})")
    if args.workers is not None and args.scheduler is not None:
        raise OptionError("give --workers (local processes) or --scheduler (a Dask "
                          "cluster), not both")
    backend = ("dask" if args.scheduler is not None
               else "processes" if args.workers is not None else None)
    workers = None if args.workers is None else check_count("--workers", args.workers, 1)

    def say(text: str) -> None:
        print(f"refsim conform: {text}", file=sys.stderr, flush=True)

    if args.all:
        make_directory(out)
        # in this process: a line as each engine's checks start and end; on
        # workers: the sweep's line
        matrix, results = run_matrix(cases=cases, seed=seed, out_dir=out, only=args.only,
                                     backend=backend, workers=workers,
                                     scheduler=args.scheduler, progress=backend is not None,
                                     announce=say if backend is None else None)
        print(matrix.table())
        for name, reason in matrix.unavailable.items():
            print(f"refsim: warning: {name} not run: {one_line(reason)}", file=sys.stderr)
        for d in matrix.divergences:
            print(f"  {d.engine:17} {d.check:22} {d.status:8} {d.reason}")
        wrote = f"wrote {out / 'index.html'}, {out / 'matrix.json'} and a page per engine"
        if matrix.unavailable:
            # a matrix with engines missing is not the check asked for
            from refsim.oracles import install_hint

            print(f"{wrote}; not run: {', '.join(sorted(matrix.unavailable))} (see the "
                  f"warnings; {install_hint(matrix.unavailable)})")
            return EXIT_CHECK_FAILED
        print(wrote)
        return 0 if matrix.ok else EXIT_CHECK_FAILED
    # MODULE is looked up in the current directory first, as `python -m`
    # does: a user's myengine.py beside them is found without PYTHONPATH
    if os.getcwd() not in sys.path:
        sys.path.insert(0, os.getcwd())
    try:
        engine = load_engine(args.engine)
    except (OracleUnavailable, ImportError) as exc:
        raise OptionError(f"engine {args.engine!r}: {exc}") from None
    # every user error is found before any work or any output
    select_capabilities(engine, args.only)
    if args.expected_failures:
        read_expected(args.expected_failures)
    make_directory(out)
    if backend is None:
        result = check_engine(engine, cases=cases, seed=seed, only=args.only,
                              expected_failures=args.expected_failures, spec=args.engine,
                              progress=say)
    else:
        from refsim.conformance.shards import check_engine_sharded

        result = check_engine_sharded(args.engine, cases=cases, seed=seed, only=args.only,
                                      expected_failures=args.expected_failures,
                                      backend=backend, workers=workers,
                                      scheduler=args.scheduler, progress=say)
    print(summary_table(result))
    json_path, page = write_engine_pages(result, out)
    expected = sum(c.status == "xfailed" for c in result.checks)
    verdict = (f"failed: {', '.join(result.failed_checks())}" if not result.ok
               else "no check failed") + (f" ({expected} expected failures)" if expected else "")
    print(f"{result.engine}: {verdict}; wrote {json_path} and {page}")
    return 0 if result.ok else EXIT_CHECK_FAILED


def _add_conform_command(commands) -> None:
    """``refsim conform`` (refsim.conformance)."""
    conform = commands.add_parser(
        "conform", help="check an engine against refsim's ground truth",
        description="Run an engine (MODULE:FACTORY, a callable returning it; see "
                    "refsim.engines) through every check its capabilities call for, "
                    "against answers that depend on no float engine. Writes "
                    "DIR/conformance.json and a self-contained DIR/index.html, prints a "
                    "table. --all runs the shipped engines and writes their matrix. "
                    "Exit status 0: every check passed (declared expected failures "
                    "aside); 1: a check failed, or --all left out an engine whose package "
                    "is missing; 2: a usage error.")
    conform.add_argument("engine", nargs="?", metavar="MODULE:FACTORY",
                         help="the engine, e.g. refsim.engines.refsim_engines:corrected")
    conform.add_argument("--all", action="store_true",
                         help="the shipped engines side by side (each with its own "
                              "expected failures)")
    conform.add_argument("-o", "--output", default="conformance", metavar="DIR",
                         help="output directory (default: conformance)")
    conform.add_argument("--cases", type=int, metavar="N",
                         help="cases in each generated set: triangle pairs, mesh poses, "
                              "boxes (default 200)")
    conform.add_argument("--seed", type=int, default=0, metavar="S",
                         help="seed of the cases and of the Hypothesis searches (default 0)")
    conform.add_argument("--only", metavar="CAPABILITY",
                         help="check one capability: triangles, pairs, collide, aabb, ode "
                              "or rigid")
    conform.add_argument("--workers", type=int, metavar="N",
                         help="run on N local processes: one engine's cases in shards of "
                              "12000, or with --all the engines side by side (the results "
                              "are the same as in one process)")
    conform.add_argument("--scheduler", metavar="ADDRESS",
                         help="run on a Dask cluster, e.g. tcp://host:8786, as --workers "
                              "does (pip install 'refsim[sweep]'; the engine's module must be "
                              "importable on the workers)")
    conform.add_argument("--expected-failures", metavar="FILE",
                         help="declared divergences, one a line: "
                              "'capability.check[class,...]  reason'")
    conform.set_defaults(run=_conform)


def _add_max_steps(command) -> None:
    """``--max-steps N`` of the commands that simulate a scene as it is given."""
    from refsim.limits import DEFAULT_MAX_STEPS, MAX_STEPS

    command.add_argument("--max-steps", type=int, metavar="N",
                         help=f"refuse a scene of more than N steps (duration over step; "
                              f"default {DEFAULT_MAX_STEPS}, at most {MAX_STEPS})")


def _add_viewer_commands(commands) -> None:
    """``refsim view`` and ``refsim replay`` (refsim.viewer; the ``viewer`` extra)."""
    from refsim.viewer import REPLAY_MAX_BYTES as DEFAULT_MAX_BYTES

    view = commands.add_parser(
        "view", help="show a scene in the browser, with controls that re-run it",
        description="Serve SCENE in the browser (viser): the bodies in the world cube, "
                    "playback, the scene's options as controls that re-run the simulation, "
                    "boxes, contacts, wall hits and energy. Prints the address; Ctrl-C "
                    "stops. Needs the viewer extra: pip install 'refsim[viewer]'.")
    view.add_argument("scene", metavar="SCENE", help="a scene file (TOML)")
    view.add_argument("--port", type=int, default=8080, metavar="N",
                      help="port to serve on (default 8080; 0 for any free port)")
    view.add_argument("--host", default="127.0.0.1", metavar="ADDRESS",
                      help="address to bind (default 127.0.0.1, this machine only)")
    _add_max_steps(view)
    view.set_defaults(run=_view)

    replay = commands.add_parser(
        "replay", help="write recorded runs (.npz) as one standalone replay page",
        description="Write the runs (refsim run SCENE -o RUN.npz) side by side, or "
                    "overlaid, as one HTML file that plays offline (play/pause, scrub, "
                    "speed). Each run's meshes come from its scene file: --scene, or the "
                    "scene the run records. Needs the viewer extra.")
    replay.add_argument("runs", nargs="+", metavar="RUN.npz", help="recorded trajectories")
    replay.add_argument("-o", "--output", required=True, metavar="OUT.html",
                        help="the replay page to write, named .html")
    replay.add_argument("--scene", action="append", metavar="SCENE.toml",
                        help="the scene of the runs (once for all, or once per run in order)")
    replay.add_argument("--overlay", action="store_true",
                        help="draw the runs in one cube, each in its own colour "
                             "(default: side by side along x)")
    replay.add_argument("--max-bytes", type=int, default=DEFAULT_MAX_BYTES, metavar="N",
                        help="size budget of the page; frames are skipped to fit "
                             f"(default {DEFAULT_MAX_BYTES // 10**6} MB)")
    replay.add_argument("--boxes", action="store_true",
                        help="draw each body's box (AABB) too")
    replay.set_defaults(run=_replay)


def _advise(args) -> int:
    """``refsim advise``: the cheapest fidelity settings within TOL
    (:func:`refsim.advisor.advice.advise`), shown by :mod:`refsim.advisor.view`."""
    import math
    import warnings

    from refsim.advisor.advice import advise
    from refsim.advisor.view import advice_document, advice_text, svg_available, svg_chart
    from refsim.errors import StateError
    from refsim.scenes.loader import load_scene
    from refsim.storage.writing import output_error, write_text_atomic

    if not (math.isfinite(args.tolerance) and args.tolerance > 0.0):
        raise StateError(f"--tolerance must be a finite number of metres > 0, "
                         f"got {args.tolerance!r}")
    for flag, value in (("--workers", args.workers), ("--repeats", args.repeats),
                        ("--max-reference-steps", args.max_reference_steps)):
        if value is not None and value < 1:
            raise StateError(f"{flag} must be at least 1, got {value}")
    if args.workers is not None and args.scheduler is not None:
        raise StateError("give --workers (local processes) or --scheduler (a Dask "
                         "cluster), not both")
    out = (None if args.output is None
           else _output_directory(args.output, "advise", "the advice as TOML and JSON, and "
                                                         "its chart"))
    if out is not None and out.exists() and not out.is_dir():
        raise output_error(out, "it is not a directory")
    if out is not None and not out.parent.is_dir():
        raise output_error(out, f"no directory {out.parent}")
    scene = load_scene(args.scene)
    if args.duration is not None:
        _with_duration(scene, args.duration)        # refused here, with the flag's name
    stem = Path(args.scene).stem
    store = args.store
    if store is None and out is not None:
        store = out / f"{stem}-advise-store"
    backend = ("dask" if args.scheduler is not None
               else "processes" if args.workers is not None else "inprocess")
    options = {} if args.repeats is None else {"repeats": args.repeats}
    if args.max_reference_steps is not None:
        options["max_reference_steps"] = args.max_reference_steps
    if out is not None:
        out.mkdir(exist_ok=True)
    advice = advise(scene, args.tolerance, duration=args.duration, backend=backend,
                    workers=args.workers, scheduler=args.scheduler, store=store,
                    progress=not args.json, **options)
    chart_path = None
    if out is not None:
        if svg_available():
            chart_path = write_text_atomic(out / f"{stem}-work-precision.svg", svg_chart(advice))
        else:
            warnings.warn("the SVG chart needs matplotlib (pip install 'refsim[report]'); "
                          "writing it as text", stacklevel=1)
            from refsim.advisor.view import text_chart

            chart_path = write_text_atomic(out / f"{stem}-work-precision.txt",
                                           text_chart(advice) + "\n")
    document = advice_document(advice, None if chart_path is None else str(chart_path))
    text = json.dumps(document, indent=1, allow_nan=False)
    if out is not None:
        from refsim.advisor.view import toml_snippet

        write_text_atomic(out / f"{stem}-advice.json", text + "\n")
        write_text_atomic(out / f"{stem}-advice.toml", toml_snippet(advice))
    if args.json:
        print(text)
    else:
        shown = None if chart_path is None else f"work-precision chart: {chart_path}"
        print(advice_text(advice, shown), end="")
    return 0


def _add_advise_command(commands) -> None:
    """``refsim advise`` (refsim.advisor; the chart needs the report extra)."""
    advise = commands.add_parser(
        "advise", help="the cheapest solver, step, collision level and box update within TOL",
        description="Hold SCENE's physics fixed and search its fidelity settings (solver, "
                    "step, collision level, box update) for the cheapest run that stays within "
                    "TOL of a reference run (rk4 at a fine step, level exact, linear boxes, "
                    "checked by halving its step). Prints the recommended [integration] and "
                    "[collision] keys, every run tried (cost: force evaluations x bodies + "
                    "narrow-phase calls, and median wall time; errors against the reference), "
                    "a work-precision chart, and the saving against the scene's own settings. "
                    "A reference that does not converge (a chaotic scene) is reported with the "
                    "horizon up to which positions are predictable.")
    advise.add_argument("scene", metavar="SCENE", help="a rigid-body scene file (TOML)")
    advise.add_argument("--tolerance", type=float, default=0.01, metavar="TOL",
                        help="metres (default 0.01): where the bodies' points are; an event "
                             "time counts by the distance it puts between two runs (|dt| x "
                             "the velocity change of the response); the end energy within "
                             "TOL / half_size of the scene's energy")
    advise.add_argument("--duration", type=float, metavar="SECONDS",
                        help="simulate this long instead of the scene's duration")
    advise.add_argument("--workers", type=int, metavar="N",
                        help="run the simulations on N local processes (default: in this one)")
    advise.add_argument("--scheduler", metavar="ADDRESS",
                        help="run them on a Dask cluster, e.g. tcp://host:8786 "
                             "(pip install 'refsim[sweep]')")
    advise.add_argument("--store", metavar="DIR",
                        help="keep each finished run here, so that an interrupted advise "
                             "resumes (default: DIR/SCENE-advise-store with -o, else none)")
    advise.add_argument("-o", "--output", metavar="DIR",
                        help="write SCENE-advice.toml, SCENE-advice.json and the chart "
                             "SCENE-work-precision.svg here (created if missing)")
    advise.add_argument("--json", action="store_true",
                        help="print one JSON document instead of the text")
    advise.add_argument("--repeats", type=int, metavar="N",
                        help="time each candidate run N times, report the median (default 3)")
    advise.add_argument("--max-reference-steps", type=int, metavar="N",
                        help="the most steps of one reference run (default 2^19)")
    advise.set_defaults(run=_advise)


class _Parser(argparse.ArgumentParser):
    """argparse with its usage errors on the one line every refsim error has,
    ``refsim: error: ...`` (argparse prints the usage first, then
    ``refsim run: error: ...``)."""

    def error(self, message: str):
        self.exit(EXIT_USER_ERROR,
                  f"refsim: error: {one_line(message)} (see {self.prog} --help)\n")


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="refsim",
        description="Reference implementation of a 1997 rigid-body N-body simulation, "
                    "checked against FCL, coal, trimesh, scipy, pybullet, MuJoCo and Drake.")
    parser.add_argument("--debug", action="store_true",
                        help="show the full traceback on errors")
    parser.add_argument("--version", action="version", version=f"refsim {version()}",
                        help="print refsim's version and exit")
    commands = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    info = commands.add_parser(
        "info", help="print facts about model files",
        description="Print each MODEL's triangles, vertices, convexity, closedness, bounds "
                    "and centroids. A bare file name (cube.ac) that is not in the current "
                    "directory names a bundled model; --bundled lists the bundled models "
                    "and scenes.")
    info.add_argument("models", nargs="*", metavar="MODEL",
                      help=".ac (refsim's reader), .obj, .stl, .ply or .off")
    info.add_argument("--bundled", action="store_true",
                      help="list the bundled models and scenes, one name a line (each can "
                           "be named so from any directory)")
    info.set_defaults(run=_info)

    run = commands.add_parser(
        "run", help="simulate a scene and write its frames (.npz)",
        description="Simulate SCENE for its [integration] duration and write an .npz. "
                    "Rigid bodies: t (frames,), position, velocity, angular_velocity "
                    "(frames, bodies, 3), orientation (frames, bodies, 3, 3), names, events, "
                    "stages, stage_seconds, settings (with the scene file's path and text, "
                    "for refsim replay; see refsim.Trajectory.load). "
                    "Particles: t, step (frames,), position and velocity (frames, N, 3), "
                    "the scene's settings as JSON (scene) and status.")
    run.add_argument("scene", metavar="SCENE",
                     help="a scene file (TOML) with [[body]] tables or a [particles] table")
    run.add_argument("-o", "--output", metavar="OUT.npz",
                     help="output file, named .npz (default: the scene's name with .npz, "
                          "here)")
    run.add_argument("--every", type=int, metavar="K",
                     help="store every K-th step (default: at most about 1000 frames for "
                          "bodies, 200 for particles); the last step is always stored")
    run.add_argument("--duration", type=float, metavar="SECONDS",
                     help="simulate this long instead of the scene's [integration] duration")
    _add_max_steps(run)
    run.set_defaults(run=_run)

    report = commands.add_parser(
        "report", help="write the HTML accuracy report (the quick one unless --full)",
        description="Measure and write the HTML accuracy report. By default the quick "
                    "report: fewer sizes, repeats and seconds, about a minute and a half "
                    "on two idle cores once numba has compiled. --full measures "
                    "everything (about twelve minutes with --workers 2 on two cores).")
    size = report.add_mutually_exclusive_group()
    size.add_argument("--quick", dest="full", action="store_false",
                      help="the quick report (the default)")
    size.add_argument("--full", dest="full", action="store_true",
                      help="every size, repeat and scene: the report the README quotes")
    report.set_defaults(full=False)          # the first of the two flags would set True
    report.add_argument("-o", "--output", default="reports/out", metavar="DIR",
                        help="output directory (default: reports/out)")
    report.add_argument("--workers", type=int, metavar="N",
                        help="run the report's sweeps (the conformance matrix, the replays, "
                             "the advisor) on N local processes; the results are the same "
                             "(default: in this process)")
    report.set_defaults(run=_report)
    _add_study_command(commands)
    _add_viewer_commands(commands)
    _add_conform_command(commands)
    _add_advise_command(commands)
    return parser


def one_line(text) -> str:
    """``text`` on one line: control characters (a newline in a file name,
    say) written as escapes, as ``repr`` writes them, so a message is always
    exactly one line of the terminal."""
    return "".join(c if c.isprintable() or c == " " else repr(c)[1:-1] for c in str(text))


def _one_line_warning(message, category, filename, lineno, file=None, line=None):
    print(f"refsim: warning: {one_line(message)}", file=sys.stderr if file is None else file)


def version() -> str:
    """refsim's version: the installed distribution's, else the package's own
    ``__version__`` (a source tree on the path without an install)."""
    from importlib.metadata import PackageNotFoundError
    from importlib.metadata import version as installed_version

    try:
        return installed_version("refsim")
    except PackageNotFoundError:
        from refsim import __version__

        return __version__


def main(argv: list[str] | None = None) -> int:
    """Run the command of ``argv`` (default: the process's arguments) and
    return its exit status. Output cut short by its reader (a pipe into
    ``head``) ends quietly with :data:`EXIT_BROKEN_PIPE`, as Python's
    documentation of SIGPIPE advises: standard output is pointed at
    ``os.devnull`` so that the interpreter's final flush cannot fail again."""
    unraisable_hook = sys.unraisablehook
    try:
        status = _main(argv)
        sys.stdout.flush()          # a broken pipe shows here, not at exit
        return status
    except BrokenPipeError:
        try:
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, sys.stdout.fileno())
        except (OSError, ValueError):   # a stream with no descriptor (a test's capture)
            pass
        return EXIT_BROKEN_PIPE
    finally:
        if sys.unraisablehook is not unraisable_hook:     # _quiet_finalizers ran
            try:
                gc.collect()        # what the signal cut short is freed while quiet
            finally:
                sys.unraisablehook = unraisable_hook


#: Commands that make many calls of the tiered kernel families
#: (:class:`refsim.kernels.Tier`): on a cold numba cache they compile them
#: in a background process (:mod:`refsim.warm`) while their first calls
#: run readable.
LONG_COMMANDS = (_conform,)

#: Commands that time refsim's kernels (the advice's wall-time saving among
#: them): they run without the tiered start
#: (``REFSIM_TIERED_START=0``, inherited by their worker processes), so
#: that on a cold cache they compile first and time the compiled kernels,
#: not readable calls made while the compile was pending.
TIMED_COMMANDS = (_report, _study, _advise)


def _main(argv: list[str] | None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if not args.debug:
        warnings.showwarning = _one_line_warning
    try:
        # SIGTERM and SIGHUP unwind like Ctrl-C, so temporary files are removed
        # `info` computes nothing numba compiles: it does not pay numba's import
        with signals_raise(), (contextlib.nullcontext() if args.run is _info
                               else compile_notices(sys.stderr)):
            if args.run in TIMED_COMMANDS:
                os.environ[TIERED_ENV] = "0"
            elif args.run in LONG_COMMANDS:
                from refsim.warm import start_in_background

                start_in_background(sys.stderr)
            return args.run(args)
    except DivergenceError as exc:
        if args.debug:
            raise
        print(f"refsim: error: {one_line(exc)}", file=sys.stderr)
        return EXIT_DIVERGED
    except RefsimError as exc:
        if args.debug:
            raise
        print(f"refsim: error: {one_line(exc)}", file=sys.stderr)
        return EXIT_USER_ERROR
    except Interrupted as exc:
        _quiet_finalizers()
        print(f"refsim: interrupted ({exc.name})", file=sys.stderr)
        return exc.exit_status
    except KeyboardInterrupt:
        _quiet_finalizers()
        print("refsim: interrupted", file=sys.stderr)
        return 130


def _drop(unraisable) -> None:
    """An unraisable exception not reported (see :func:`_quiet_finalizers`)."""


def _quiet_finalizers() -> None:
    """After an interruption, errors raised in finalizers are not reported.

    A signal can arrive inside a constructor, as numba compiles for example:
    llvmlite's ``OutputString.__init__`` cut short before it sets
    ``_owned`` fails in ``__del__`` when the unwound stack frees it, and
    Python prints that as "Exception ignored in ..." with a traceback after
    the one line an interruption gets. The process is ending; nothing is
    left for such a report to explain. :func:`main` restores the hook.
    """
    sys.unraisablehook = _drop


if __name__ == "__main__":
    sys.exit(main())
