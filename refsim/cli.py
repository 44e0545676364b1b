"""The ``refsim`` command line.

    refsim info MODEL                  facts about a model file
    refsim run SCENE [-o OUT.npz] [--every K]
                                       simulate a particle scene, write its frames
    refsim report [--quick] [-o DIR]   write the HTML accuracy report

A user's mistake (a missing or malformed file, a bad scene) prints one line
naming the file and the line or key, and exits with status 2; ``--debug``
shows the traceback instead. A run that diverges prints one line naming the
step and time, writes the frames computed before it, and exits with status 3.
Anything else is a bug in refsim and keeps its traceback. Output files are
written whole or not at all (a temporary file, then ``os.replace``).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import tempfile
import warnings
from dataclasses import asdict, dataclass
from pathlib import Path

from refsim.errors import DivergenceError, RefsimError, SceneError

EXIT_USER_ERROR = 2
EXIT_DIVERGED = 3

#: ``refsim run`` stores about this many frames unless ``--every`` says
#: otherwise: enough to replay smoothly, and 200 frames of 10 000 particles
#: are 96 MB of float64.
DEFAULT_FRAMES = 200

#: ``refsim run`` refuses to store more frame data than this (positions and
#: velocities, 48 bytes a particle a frame) and asks for a larger ``--every``:
#: the frames are held in memory until the file is written.
MAX_FRAME_BYTES = 4 * 10**9


def _info(args) -> int:
    from refsim.models.facts import describe, format_facts
    from refsim.models.loading import load_model

    for i, path in enumerate(args.models):
        if i:
            print()
        print(format_facts(describe(load_model(path), name=str(path))))
    return 0


@dataclass(frozen=True)
class ParticleFrames:
    """Stored frames of a particle run.

    Attributes
    ----------
    step : numpy.ndarray
        (frames,) int64 step index of each frame (0 is the initial state).
    t : numpy.ndarray
        (frames,) times, ``step * h``.
    position, velocity : numpy.ndarray
        (frames, N, 3) float64.
    """

    step: object
    t: object
    position: object
    velocity: object


def run_particles(config, n_steps: int, every: int) -> ParticleFrames:
    """Run a :class:`~refsim.particles.system.ParticleSystem` from
    ``config.initial_state()`` for ``n_steps`` steps, keeping every
    ``every``-th state and the last one.

    Raises
    ------
    DivergenceError
        The state became non-finite. ``step`` and ``time`` are those of the
        first non-finite step (the system checks once per stored frame; the
        frame interval that failed is replayed step by step from its start,
        which reproduces the same arithmetic bit for bit). ``partial`` holds
        the frames stored before it.
    """
    import numpy as np

    from refsim.particles.system import ParticleSystem

    h = config.step
    system = ParticleSystem(config)
    steps = [0]
    xs, vs = [system.positions.copy()], [system.velocities.copy()]

    def frames():
        step = np.array(steps, dtype=np.int64)
        return ParticleFrames(step, step * h, np.stack(xs), np.stack(vs))

    while system.steps < n_steps:
        block = min(every, n_steps - system.steps)
        try:
            # Overflow on the way to divergence is expected and detected below,
            # so numpy's warnings would only repeat it.
            with np.errstate(over="ignore", invalid="ignore"):
                system.run(block)
        except DivergenceError:
            first = _first_non_finite_step(config, xs[-1], vs[-1], block)
            step = steps[-1] + first
            raise DivergenceError("particle state is not finite", step=step, time=step * h,
                                  partial=frames()) from None
        steps.append(system.steps)
        xs.append(system.positions.copy())
        vs.append(system.velocities.copy())
    return frames()


def _first_non_finite_step(config, x, v, block: int) -> int:
    """Steps from the state ``(x, v)`` until it is first non-finite (at most ``block``)."""
    import numpy as np

    from refsim.particles.system import ParticleSystem

    system = ParticleSystem(config, positions=x, velocities=v)
    for i in range(1, block + 1):
        with np.errstate(over="ignore", invalid="ignore"):
            system.step()
        if not np.isfinite(system.state).all():
            return i
    return block


def write_npz_atomic(path: Path, arrays: dict) -> None:
    """``numpy.savez`` to ``path`` through a temporary file in the same
    directory and ``os.replace``: readers see the old file or the whole new
    one, and an error or Ctrl-C leaves no partial file."""
    import numpy as np

    path = Path(path)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as handle:
            np.savez(handle, **arrays)
        mask = os.umask(0)
        os.umask(mask)
        os.chmod(tmp, 0o666 & ~mask)        # mkstemp makes 0600; give what open() would
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


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
    import numpy as np

    from refsim.scenes.loader import load_scene
    from refsim.solvers.integrate import STEP_COUNT_RTOL  # duration / step tolerance

    scene = load_scene(args.scene)
    if scene.bodies:
        raise RefsimError(f"{args.scene}: rigid-body simulation is not implemented yet "
                          "(issue 6)")
    config = scene.particles
    integration = scene.integration
    ratio = integration.duration / integration.step
    n_steps = round(ratio)
    if abs(ratio - n_steps) > STEP_COUNT_RTOL * max(n_steps, 1):
        raise SceneError(f"duration / step = {ratio:.9g} is not a whole number of steps",
                         scene.path, "integration.duration")
    if args.every is None:
        every = max(1, math.ceil(n_steps / (DEFAULT_FRAMES - 1)))
    elif args.every < 1:
        raise RefsimError(f"--every must be at least 1, got {args.every}")
    else:
        every = args.every
    n_frames = math.ceil(n_steps / every) + 1
    if n_frames * config.count * 48 > MAX_FRAME_BYTES:
        raise RefsimError(f"{n_frames} frames of {config.count} particles would take "
                          f"{n_frames * config.count * 48 / 1e9:.1f} GB; store fewer with "
                          f"--every (at most {MAX_FRAME_BYTES / 1e9:g} GB)")
    out = Path(args.output) if args.output else Path(Path(args.scene).stem + ".npz")
    if not out.parent.is_dir():
        raise RefsimError(f"{out}: cannot write: no directory {out.parent}")

    def write(frames: ParticleFrames, status: str) -> None:
        arrays = {"t": frames.t, "step": frames.step, "position": frames.position,
                  "velocity": frames.velocity,
                  "scene": np.array(json.dumps(_settings(scene, every), sort_keys=True)),
                  "status": np.array(status)}
        try:
            write_npz_atomic(out, arrays)
        except OSError as exc:
            raise RefsimError(f"{out}: cannot write: {exc.strerror or exc}") from exc

    try:
        frames = run_particles(config, n_steps, every)
    except DivergenceError as exc:
        partial = exc.partial
        status = f"diverged at step {exc.step}, t = {exc.time:.6g}"
        write(partial, status)
        raise DivergenceError(
            f"particle state is not finite; wrote the {len(partial.t)} frames before it "
            f"(t = 0 to {partial.t[-1]:.6g}) to {out}", step=exc.step, time=exc.time) from None
    write(frames, "complete")
    print(f"wrote {out}: {len(frames.t)} frames of {config.count} particles, "
          f"t = 0 to {frames.t[-1]:.6g} ({config.solver}, h = {config.step:g}, "
          f"every {every} steps)")
    return 0


def _report(args) -> int:
    from refsim.report.build import build_report

    out = Path(args.output)
    try:
        page = build_report(out, quick=args.quick)
    except OSError as exc:
        raise RefsimError(f"{out}: cannot write the report: {exc.strerror or exc}") from exc
    print(f"wrote {page}")
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="refsim",
        description="Reference implementation of a 1997 rigid-body N-body simulation, "
                    "checked against FCL, trimesh, scipy and pybullet.")
    parser.add_argument("--debug", action="store_true",
                        help="show the full traceback on errors")
    commands = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    info = commands.add_parser("info", help="print facts about model files")
    info.add_argument("models", nargs="+", metavar="MODEL",
                      help=".ac (refsim's reader), .obj, .stl, .ply or .off")
    info.set_defaults(run=_info)

    run = commands.add_parser(
        "run", help="simulate a particle scene and write its frames (.npz)",
        description="Simulate the particle system of SCENE for its [integration] "
                    "duration and write an .npz with t (frames,), step (frames,), "
                    "position and velocity (frames, N, 3), the scene's settings as JSON "
                    "(scene) and status. Rigid bodies are not simulated yet.")
    run.add_argument("scene", metavar="SCENE", help="a scene file (TOML) with [particles]")
    run.add_argument("-o", "--output", metavar="OUT.npz",
                     help="output file (default: the scene's name with .npz, here)")
    run.add_argument("--every", type=int, metavar="K",
                     help=f"store every K-th step (default: about {DEFAULT_FRAMES} frames); "
                          "the last step is always stored")
    run.set_defaults(run=_run)

    report = commands.add_parser("report", help="write the HTML accuracy report")
    report.add_argument("--quick", action="store_true",
                        help="fewer sizes and repeats (under a minute)")
    report.add_argument("-o", "--output", default="reports/out", metavar="DIR",
                        help="output directory (default: reports/out)")
    report.set_defaults(run=_report)
    return parser


def _one_line_warning(message, category, filename, lineno, file=None, line=None):
    print(f"refsim: warning: {message}", file=sys.stderr if file is None else file)


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if not args.debug:
        warnings.showwarning = _one_line_warning
    try:
        return args.run(args)
    except DivergenceError as exc:
        if args.debug:
            raise
        print(f"refsim: error: {exc}", file=sys.stderr)
        return EXIT_DIVERGED
    except RefsimError as exc:
        if args.debug:
            raise
        print(f"refsim: error: {exc}", file=sys.stderr)
        return EXIT_USER_ERROR
    except KeyboardInterrupt:
        print("refsim: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
